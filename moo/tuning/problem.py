r"""A tuning problem: a design family, a set of plants and goals, as one pymoo ``Problem``.

:class:`TuningProblem` evaluates a whole population at once:

1. check the population ``Z`` (B, n_var) and design all gains with the
   family (:meth:`DesignFamily.gains <moo.tuning.families.DesignFamily>`);
2. screen the closed loops ``F_s + G_s K`` of the ``S`` scenario plants for
   Schur stability (:func:`robustctl.is_schur_stable`), and compute the
   largest spectral radius of the designs unstable somewhere
   (:func:`robustctl.spectral_radius`);
3. call every goal (objective or constraint) once, on the gains of the
   designs that were computed and stabilise every scenario only;
4. apply the penalty rule (:func:`penalise`).

The penalty rule (Morais et al. 2022, Section 3.1) makes every objective
finite and ranks the designs: with ``p`` the ``penalty``,

* a design the family could not compute gets ``2 p`` on every objective;
* a design unstable in some scenario gets ``p min(rho, 2)`` on every
  objective (``rho`` its largest closed-loop spectral radius over the
  scenarios, so the MOEA still prefers the less unstable ones);
* a design for which a goal returned NaN or inf is *flagged* and gets ``p``
  on every objective;
* the others get their goal values, clipped at ``p``.

Constraints (``g <= 0`` holds) of the penalised designs get the same positive
value as their objectives, so they are infeasible too.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import moocore
import numpy as np
from pymoo.core.problem import Problem

import robustctl as rc
from robustctl.validation import check_positive_scalar

from ..validation import as_float_array, as_matrix, check_choice, check_int
from .families import DesignFamily, FamilyControllers, FamilyGains, bound_vector, check_bounds, population
from .goals import check_scenarios
from .loops import Controllers, check_controllers, closed_loops, count, is_output_feedback, take, with_outputs
from .loops import stability as loop_stability

__all__ = ["TuningProblem", "penalise", "goal_name", "Goal"]

#: A goal: ``f(K (B, m, n), plants) -> (B,)``, smaller is better (a constraint holds where ``<= 0``).
Goal = Callable[[np.ndarray, list[rc.Plant]], Any]


def penalise(J: np.ndarray, ok: np.ndarray, stable: np.ndarray, rho: np.ndarray, penalty: float) -> np.ndarray:
    r"""Apply the penalty rule (module docstring) to raw objectives ``J`` (B, M).

    Parameters
    ----------
    J : (B, M) ndarray
        Raw objective values (NaN or inf where a goal gave no number).
    ok : (B,) bool ndarray
        The design was computed.
    stable : (B,) bool ndarray
        Its closed loops are Schur-stable in every scenario.
    rho : (B,) ndarray
        The largest closed-loop spectral radius over the scenarios (read only
        where ``ok & ~stable``; NaN there counts as 2).
    penalty : float
        The penalty ``p``.

    Returns
    -------
    (B, M) ndarray
        Every value finite; the penalised ones ``>= penalty``.

    See Also
    --------
    TuningProblem : applies it to every population.

    Notes
    -----
    Row by row,

    .. math::

        f_{b} = \begin{cases}
            2 p & \text{design } b \text{ not computed}, \\
            p \min(\rho_b, 2) & \text{computed, unstable in some scenario}, \\
            \min(J_{b}, p) & \text{otherwise (non-finite entries: } p).
        \end{cases}

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Section 3.1.

    Examples
    --------
    A stable design keeps its values, an unstable one (``rho = 1.5``) gets
    ``1.5 p``, a failed one ``2 p``:

    >>> import numpy as np
    >>> from moo.tuning import penalise
    >>> J = np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]])
    >>> penalise(J, ok=np.array([True, True, False]), stable=np.array([True, False, True]),
    ...          rho=np.array([np.nan, 1.5, np.nan]), penalty=10.0)
    array([[ 1.,  2.],
           [15., 15.],
           [20., 20.]])
    """
    out = np.where(np.isfinite(J), np.minimum(J, penalty), penalty)
    unstable = ok & ~stable
    out[unstable] = (penalty * np.minimum(np.nan_to_num(rho[unstable], nan=2.0), 2.0))[:, None]
    out[~ok] = 2.0 * penalty
    return out


def goal_name(goal, index: int, kind: str) -> str:
    """A readable name of a goal: its ``name`` attribute, a function's name, or ``kind[index]``."""
    name = getattr(goal, "name", None)
    if isinstance(name, str) and name:
        return name
    fn = getattr(goal, "__name__", None)
    if isinstance(fn, str) and fn != "<lambda>":
        return fn
    return f"{kind}[{index}]"


def _goals(goals, kind: str) -> tuple[list, list[str]]:
    if callable(goals):
        goals = [goals]
    if isinstance(goals, (str, bytes)) or not isinstance(goals, Sequence):
        raise TypeError(f"{kind} must be a list of callables f(K, plants), got {type(goals).__name__}")
    goals = list(goals)
    for i, g in enumerate(goals):
        if not callable(g):
            raise TypeError(f"{kind}[{i}] must be callable as f(K, plants), got {type(g).__name__}")
    names = [goal_name(g, i, kind) for i, g in enumerate(goals)]
    return goals, names


def _with_outputs(plants: Sequence[rc.Plant], plant: rc.Plant) -> list[rc.Plant]:
    """The scenarios as an output feedback reads them: ``plant``'s ``C``, ``D`` where a scenario has none."""
    for i, p in enumerate(plants):
        if p.has_outputs and p.p != plant.p:
            raise ValueError(f"scenarios[{i}] has p={p.p} outputs, the family's controllers read p={plant.p}")
    return [with_outputs(p, plant) for p in plants]


def _finite(K: Controllers) -> np.ndarray:
    """(B,) designs without NaN or inf entries."""
    if is_output_feedback(K):
        return np.all([np.isfinite(M).all(axis=(1, 2)) for M in (K.Ac, K.Bc, K.Cc, K.Dc)], axis=0)
    return np.all(np.isfinite(K), axis=(1, 2))


def _zeroed(K: Controllers) -> Controllers:
    """The designs with their non-finite entries set to 0 (flagged separately), read-only."""
    if is_output_feedback(K):
        if _finite(K).all():
            return K
        return rc.ControllerBatch(K.plant, *(np.nan_to_num(M, nan=0.0, posinf=0.0, neginf=0.0)
                                             for M in (K.Ac, K.Bc, K.Cc, K.Dc)))
    out = np.where(np.isfinite(K), K, 0.0)
    out.flags.writeable = False
    return out


def _ref_point(value, name: str, default: np.ndarray) -> np.ndarray:
    if value is None:
        return default.copy()
    arr = as_matrix(value, name, rows=1, cols=default.size, cols_what="the number of objectives").ravel()
    return arr


class TuningProblem(Problem):
    r"""Tune a state feedback of a design family against a set of plants (a pymoo ``Problem``).

    ``n_var = family.n_var``, ``n_obj = len(objectives)``, ``n_ieq_constr =
    len(constraints)``; the population is evaluated at once (module docstring:
    the screen and the penalty rule).

    Parameters
    ----------
    family : DesignFamily
        ``z`` -> gains (:class:`~moo.tuning.RLQRFamily`, :class:`~moo.tuning.LQRFamily` or your own).
    scenarios : list of robustctl.Plant
        The plant set (same ``n``, ``m``, ``dt``; the family's ``n_states``, ``n_inputs``).
        A design must stabilise every one of them.
    objectives : list of callables
        Goals ``f(K, plants) -> (B,)``, ``K`` (B, m, n) the gains of the
        designs that stabilise every scenario, ``plants`` the scenario list;
        smaller is better. A goal with a ``check(plants)`` method has it called
        once here (it raises for arguments that do not fit the plants).
    constraints : list of callables
        Goals of the same form; a design is feasible where every value is ``<= 0``.
    xl, xu : float or (n_var,) array_like, optional
        Bounds of ``z`` (default: the family's).
    penalty : float
        ``p`` of the penalty rule; it must exceed every goal value of an
        acceptable design (values above it are clipped to it). Default ``1e6``.
    hv_ref_point : (n_obj,) array_like, optional
        Hypervolume reference point of the runs' records. Default: from
        ``reference_samples`` designs drawn uniformly within the bounds
        (:meth:`sample_reference_points`, seed 0, computed when first needed):
        the nadir of their acceptable non-dominated designs enlarged by 25 %
        of the front's extent, a point on the scale of good designs. If none
        of the sampled designs is acceptable, ``penalty`` on every objective
        (valid, but far above good designs). ``hv_ref_source`` says which.
    molsp_ref_point : (n_obj,) array_like, optional
        MO-LSP's leader reference point (MO-LSP chooses its leaders among the
        designs that dominate it); default the sampled one of
        :meth:`sample_reference_points` (every acceptable sampled design
        dominates it), or ``hv_ref_point`` when that is given.
    reference_samples : int
        Designs sampled for the default reference points (default 500).

    Attributes
    ----------
    scenarios : list of robustctl.Plant
        The checked scenario list.
    objectives, constraints : list of callables
        The goals.
    objective_names, constraint_names : list of str
        Their labels (a goal's ``name``, a function's name, or ``objectives[i]``).
    hv_ref_point, molsp_ref_point : (n_obj,) ndarray
        The reference points (the defaults are sampled on first access).
    hv_ref_source : str
        Where ``hv_ref_point`` comes from: ``"given"``, ``"sampled designs"``
        or ``"penalty"`` (no sampled design was acceptable).
    feedback : {"state", "output"}
        The family's kind: the goals get gains (B, m, n) or an
        :class:`robustctl.ControllerBatch`; for an output feedback the
        scenarios without an output model get the family plant's ``C``, ``D``.
    last_flags : (B,) object ndarray
        Why each design of the last evaluated population was penalised
        (``""`` for none): the family's reason, ``"unstable"``, or
        ``"<goal> returned nan"`` (or ``inf``).

    Raises
    ------
    TypeError
        A family that lacks a member of the :class:`~moo.tuning.DesignFamily`
        protocol, a goal that is not callable.
    ValueError
        Scenarios of different sizes (naming ``scenarios``), a family whose
        gain size does not fit them, inverted bounds (naming ``xl``/``xu``),
        a goal's ``check`` failing, a reference point of the wrong length.
        During evaluation: a goal that returns anything but ``(B,)`` numbers
        (naming the goal).

    See Also
    --------
    moo.tuning.tune : run a MOEA on it.
    penalise : the penalty rule.
    moo.tuning.select : pick one design of a front.

    Notes
    -----
    For a population :math:`z_1, \dots, z_B` with gains :math:`K_b` and the
    scenarios :math:`(F_s, G_s)`, a design is acceptable when it is computed
    and :math:`\rho(F_s + G_s K_b) < 1` for every :math:`s`; its objectives
    are then :math:`f_j(K_b, \{P_s\})`, and the others are ranked by the
    penalty rule (:func:`penalise`).

    References
    ----------
    .. [1] D. C. Morais et al., "Robust path-following control design of heavy
       vehicles based on multiobjective evolutionary optimization", Expert
       Systems with Applications 192 (2022) 116304, Section 3.1.

    Examples
    --------
    An LQR family on a double integrator whose input gain is known to 20 %,
    scored by the mean squared error and the peak input of a response:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo import tuning
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> scenarios = [rc.Plant(plant.F, plant.G * s, dt=0.1) for s in (0.8, 1.0, 1.2)]
    >>> response = tuning.Response(x0=[1.0, 0.0], steps=50)
    >>> prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios,
    ...                             [response.error(), response.peak_input()])
    >>> prob
    TuningProblem(family=LQRFamily(n=2, m=1, n_var=3), S=3, n_var=3, objectives=['mse(x)', 'peak |u|'], constraints=[])
    >>> Z = np.zeros((1, 3))                        # Q = I, R = 1
    >>> F = prob.evaluate(Z)
    >>> K = prob.gains(Z).K
    >>> np.allclose(F, [[goal(K, scenarios)[0] for goal in prob.objectives]])
    True
    """

    def __init__(self, family: DesignFamily, scenarios: Sequence[rc.Plant], objectives: Sequence[Goal],
                 constraints: Sequence[Goal] = (), *, xl=None, xu=None, penalty: float = 1e6,
                 hv_ref_point=None, molsp_ref_point=None, reference_samples: int = 500):
        for attr in ("n_var", "xl", "xu", "n_states", "n_inputs", "gains"):
            if not hasattr(family, attr):
                raise TypeError(f"family must follow the DesignFamily protocol (missing {attr!r}), "
                                f"got {type(family).__name__}")
        self.family = family
        self.feedback = check_choice(getattr(family, "feedback", "state"), "family.feedback", ("state", "output"))
        plant = getattr(family, "plant", None)
        if self.feedback == "output" and not isinstance(plant, rc.Plant):
            raise TypeError("family: an output-feedback family needs a plant attribute (a robustctl.Plant with the "
                            "outputs its controllers read)")
        continuous = isinstance(plant, rc.Plant) and plant.dt is None and self.feedback == "output"
        self.scenarios = check_scenarios(scenarios, "scenarios", continuous=continuous)
        n, m = self.scenarios[0].n, self.scenarios[0].m
        if (family.n_states, family.n_inputs) != (n, m):
            raise ValueError(f"family gives controllers for n={family.n_states} states and m={family.n_inputs} "
                             f"inputs, but the scenarios have m={m} inputs and n={n} states")
        if isinstance(plant, rc.Plant) and plant.dt != self.scenarios[0].dt:
            raise ValueError(f"family.plant has dt={plant.dt} but the scenarios have dt={self.scenarios[0].dt}: "
                             "design the family on a plant of the scenarios' sampling time")
        self._outputs_of = plant if self.feedback == "output" else None      # the C, D the controllers read
        if self._outputs_of is not None:
            self.scenarios = _with_outputs(self.scenarios, self._outputs_of)
        self.objectives, self.objective_names = _goals(objectives, "objectives")
        if not self.objectives:
            raise ValueError("objectives must not be empty")
        self.constraints, self.constraint_names = _goals(constraints, "constraints")
        for goal in (*self.objectives, *self.constraints):
            check = getattr(goal, "check", None)
            if callable(check):
                check(self.scenarios)
        n_var = int(family.n_var)
        lo = bound_vector(family.xl if xl is None else xl, "xl", np.zeros(n_var))
        hi = bound_vector(family.xu if xu is None else xu, "xu", np.zeros(n_var))
        check_bounds(lo, hi)
        self.penalty = check_positive_scalar(penalty, "penalty")
        n_obj = len(self.objectives)
        self._hv_ref = None if hv_ref_point is None else _ref_point(hv_ref_point, "hv_ref_point", np.zeros(n_obj))
        self._molsp_ref = None if molsp_ref_point is None else \
            _ref_point(molsp_ref_point, "molsp_ref_point", np.zeros(n_obj))
        if self._molsp_ref is None and self._hv_ref is not None:
            self._molsp_ref = self._hv_ref.copy()
        self.hv_ref_source = "given" if self._hv_ref is not None else "sampled designs (not yet drawn)"
        self.reference_samples = check_int(reference_samples, "reference_samples", 2)
        self._plants = tuple(self.scenarios)               # what the goals get (immutable)
        self.last_flags = np.zeros(0, dtype=object)
        super().__init__(n_var=n_var, n_obj=n_obj, n_ieq_constr=len(self.constraints), xl=lo, xu=hi, vtype=float)

    # -- reference points ------------------------------------------------------------
    @property
    def hv_ref_point(self) -> np.ndarray:
        """The hypervolume reference point (the default is sampled on first access; see the class docstring)."""
        if self._hv_ref is None:
            self._sample_defaults()
        assert self._hv_ref is not None
        return self._hv_ref

    @hv_ref_point.setter
    def hv_ref_point(self, value) -> None:
        self._hv_ref = _ref_point(value, "hv_ref_point", np.zeros(self.n_obj))
        self.hv_ref_source = "given"

    @property
    def molsp_ref_point(self) -> np.ndarray:
        """MO-LSP's reference point (the default is sampled on first access)."""
        if self._molsp_ref is None:
            self._sample_defaults()
        assert self._molsp_ref is not None
        return self._molsp_ref

    @molsp_ref_point.setter
    def molsp_ref_point(self, value) -> None:
        self._molsp_ref = _ref_point(value, "molsp_ref_point", np.zeros(self.n_obj))

    def _sample_defaults(self) -> None:
        """Fill the reference points not given from :meth:`sample_reference_points` (else the penalty)."""
        try:
            hv, molsp = self.sample_reference_points(self.reference_samples, seed=0)
            source = "sampled designs"
        except ValueError:
            hv = molsp = np.full(self.n_obj, self.penalty)
            source = f"penalty: none of {self.reference_samples} sampled designs was acceptable"
        if self._hv_ref is None:
            self._hv_ref, self.hv_ref_source = hv, source
        if self._molsp_ref is None:
            self._molsp_ref = molsp

    # -- designs and closed loops ----------------------------------------------------
    @property
    def n_states(self) -> int:
        """Number of states of the scenario plants."""
        return self.scenarios[0].n

    @property
    def n_inputs(self) -> int:
        """Number of inputs of the scenario plants."""
        return self.scenarios[0].m

    def population(self, Z, name: str = "Z") -> np.ndarray:
        """``Z`` as a finite (B, n_var) float array (a single (n_var,) vector becomes B = 1)."""
        return population(Z, self.n_var, name)

    def gains(self, Z) -> FamilyGains | FamilyControllers:
        """The family's designs of a population ``Z`` (B, n_var), checked.

        :class:`~moo.tuning.FamilyGains` (``K`` (B, m, n)) for a state-feedback
        family, :class:`~moo.tuning.FamilyControllers` for an output-feedback
        one; failed designs have NaN rows and ``ok`` False.
        """
        z = self.population(Z)
        fg = self.family.gains(z)
        B = z.shape[0]
        if self.feedback == "output":
            if not isinstance(fg, FamilyControllers) or len(fg.controllers) != B:
                raise ValueError(f"family.gains must return FamilyControllers of {B} designs (an output-feedback "
                                 f"family), got {fg!r}")
            batch = fg.controllers
            check_controllers(batch, self.scenarios, "family.gains(...).controllers")
            ok = np.asarray(fg.ok, dtype=bool) & _finite(batch)
            return FamilyControllers(batch, ok, np.asarray(fg.reason, dtype=object))
        K = np.asarray(getattr(fg, "K", None), dtype=float)
        if K.shape != (B, self.n_inputs, self.n_states):
            raise ValueError(f"family.gains returned K of shape {K.shape}, expected "
                             f"({B}, {self.n_inputs}, {self.n_states})")
        ok = np.asarray(fg.ok, dtype=bool) & np.all(np.isfinite(K), axis=(1, 2))
        return FamilyGains(K=np.where(ok[:, None, None], K, np.nan), ok=ok, reason=np.asarray(fg.reason, dtype=object))

    def designs(self, Z) -> tuple[Controllers, np.ndarray, np.ndarray]:
        """``(controllers, ok, reason)`` of a population: gains (B, m, n) or a :class:`robustctl.ControllerBatch`."""
        fg = self.gains(Z)
        return (fg.controllers if isinstance(fg, FamilyControllers) else fg.K), fg.ok, fg.reason

    def check_gains(self, K) -> Controllers:
        """The designs ``K`` checked: (B, m, n) gains, or an output-feedback problem's controllers.

        Gains may have NaN rows (failed designs); one (m, n) gain becomes
        B = 1. An output-feedback problem takes a
        :class:`robustctl.ControllerBatch` of the scenarios' plant.
        """
        if is_output_feedback(K):
            return check_controllers(K, self.scenarios, "K")
        if self.feedback == "output":
            raise TypeError(f"K must be a robustctl.ControllerBatch for this output-feedback problem, got "
                            f"{type(K).__name__}")
        K = as_float_array(K, "K")
        if K.ndim == 2:
            K = K[None]
        if K.ndim != 3 or K.shape[1:] != (self.n_inputs, self.n_states):
            raise ValueError(f"K must have shape (B, {self.n_inputs}, {self.n_states}), got shape {K.shape}")
        return K

    def _plants_of(self, scenarios) -> tuple[rc.Plant, ...]:
        if scenarios is None:
            return self._plants
        plants = check_scenarios(scenarios, "scenarios", continuous=not self.scenarios[0].is_discrete)
        if self._outputs_of is not None:
            plants = _with_outputs(plants, self._outputs_of)
        return tuple(plants)

    def closed_loops(self, K, scenarios: Sequence[rc.Plant] | None = None) -> np.ndarray:
        """The closed loops (B, S, N, N) of the designs ``K`` on the scenarios (default the problem's).

        ``F_s + G_s K`` for gains (``N = n``), the loops in ``(x, x_c)`` for a
        :class:`robustctl.ControllerBatch` (``N = n + n_c``); NaN for designs
        with non-finite entries.
        """
        Kc = self.check_gains(K)
        A = np.array(closed_loops(_zeroed(Kc), self._plants_of(scenarios)).A)
        A[~_finite(Kc)] = np.nan
        return A

    def closed_loop_radius(self, K, scenarios: Sequence[rc.Plant] | None = None) -> np.ndarray:
        """Spectral radius (B, S) of the closed loop per scenario (inf for non-finite designs)."""
        return np.asarray(rc.spectral_radius(self.closed_loops(K, scenarios)))     # inf where A is NaN

    def stability(self, K, scenarios: Sequence[rc.Plant] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(stable (B, S), rho (B,))``: stability per scenario, and the worst "radius" of the unstable designs.

        ``rho`` is the largest spectral radius over the scenarios (continuous
        plants: ``exp`` of the largest real part of the poles) of the designs
        unstable somewhere (NaN for the others, which need no eigenvalues; inf
        for non-finite designs and ill-posed loops).
        """
        Kc = self.check_gains(K)
        finite = _finite(Kc)
        stable, rho = loop_stability(closed_loops(_zeroed(Kc), self._plants_of(scenarios)))
        stable &= finite[:, None]
        rho[~finite] = np.inf
        return stable, rho

    # -- goals ---------------------------------------------------------------------
    def _call(self, goal, name: str, K: Controllers, plants: tuple[rc.Plant, ...]) -> np.ndarray:
        """``goal(K, plants)``, its value checked (``K`` read-only and ``plants`` a tuple: see :meth:`_goals_of`)."""
        B = count(K)
        value = goal(K, plants)
        arr = np.asarray(value)
        real = arr.dtype.kind in "biuf" or (arr.dtype.kind == "O" and all(
            isinstance(v, (int, float, np.integer, np.floating)) for v in arr.ravel()))
        if not real:
            kind = {"c": "complex", "U": "str", "S": "bytes"}.get(arr.dtype.kind, "objects")
            raise ValueError(f"goal {name!r} must return real numbers ({B}, one per design), got "
                             f"{type(value).__name__} of {kind} (dtype {arr.dtype})")
        arr = arr.astype(np.float64)
        if arr.shape != (B,):
            raise ValueError(f"goal {name!r} must return shape ({B},) (one value per design), got shape {arr.shape}")
        return arr

    def evaluate_gains(self, K, scenarios: Sequence[rc.Plant] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Goal values of given designs on the scenarios (default the problem's): ``(F (B, n_obj), G (B, n_constr))``.

        ``K``: gains (B, m, n) or a :class:`robustctl.ControllerBatch`. Every
        goal is called once, on the designs that stabilise every scenario; the
        others, and designs with NaN entries, get ``+inf``. No penalty, no
        clipping; a goal's NaN stays NaN.
        """
        Kc = self.check_gains(K)
        plants = self._plants_of(scenarios)
        stable, _ = self.stability(Kc, plants)
        run = stable.all(axis=1)
        B = count(Kc)
        F = np.full((B, self.n_obj), np.inf)
        G = np.full((B, self.n_ieq_constr), np.inf)
        if run.any():
            F[run], G[run] = self._goals_of(take(Kc, run), plants)
        return F, G

    def _goals_of(self, K: Controllers, plants: tuple[rc.Plant, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Objective and constraint values (B, n_obj), (B, n_constr) of the designs ``K``, every goal called once.

        Every goal gets the same read-only designs (``take`` copies gains
        read-only; a :class:`robustctl.ControllerBatch` is frozen) and the same
        tuple of plants: a goal cannot change what the next one sees (goals
        that share a simulation recognise the same objects).
        """
        B = count(K)
        J = np.empty((B, self.n_obj))
        C = np.empty((B, self.n_ieq_constr))
        for j, (g, name) in enumerate(zip(self.objectives, self.objective_names, strict=True)):
            J[:, j] = self._call(g, name, K, plants)
        for j, (g, name) in enumerate(zip(self.constraints, self.constraint_names, strict=True)):
            C[:, j] = self._call(g, name, K, plants)
        return J, C

    def sample_reference_points(self, n: int = 500, *, seed=0, margin: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
        r"""Reference points from the scale of the objectives, by the rule the paper's two MOPs use.

        ``n`` designs are drawn uniformly from the bounds and evaluated; among
        the *acceptable* ones (not penalised, feasible) the non-dominated set
        has the ideal point ``f^-`` and the nadir point ``f^+``, and the
        acceptable designs reach at most ``f^max``. With ``d = f^+ - f^-``
        (replaced by ``|f^+|``, or 1, where it is zero),

        .. math::

            r_{hv} = f^+ + \text{margin}\; d, \qquad
            r_{molsp} = \max(f^{max}, f^+) + \text{margin}\; d,

        so every non-dominated sampled design dominates ``r_hv`` and every
        acceptable one ``r_molsp`` (MO-LSP then finds leaders from the first
        random generation on). Pass them to the constructor (or set the
        attributes) to get hypervolumes on the scale of good designs.

        Parameters
        ----------
        n : int
            Sample size.
        seed : int or numpy Generator-compatible seed
        margin : float
            Relative enlargement beyond the sample's nadir.

        Returns
        -------
        hv_ref_point, molsp_ref_point : (n_obj,) ndarray

        Raises
        ------
        ValueError
            No acceptable design in the sample (enlarge ``n`` or revise the bounds).
        """
        n = check_int(n, "n", 2)
        margin = check_positive_scalar(margin, "margin")
        Z = np.random.default_rng(seed).uniform(self.xl, self.xu, (n, self.n_var))
        out = self.evaluate(Z, return_as_dictionary=True)
        F = np.asarray(out["F"], dtype=float)
        ok = np.all(self.penalty > F, axis=1) & (self.last_flags == "")
        if self.n_ieq_constr:
            ok &= np.all(np.asarray(out["G"]) <= 0.0, axis=1)
        if not ok.any():
            raise ValueError(f"n: none of the {n} sampled designs is acceptable (all penalised or infeasible); "
                             "sample more or narrow the bounds")
        Fa = F[ok]
        nd = Fa[moocore.is_nondominated(Fa, keep_weakly=True)]
        lo, hi = nd.min(axis=0), nd.max(axis=0)
        d = hi - lo
        d = np.where(d > 0, d, np.where(np.abs(hi) > 0, np.abs(hi), 1.0))
        return hi + margin * d, np.maximum(Fa.max(axis=0), hi) + margin * d

    # -- pymoo hooks -----------------------------------------------------------------
    def evaluate(self, X, *args, **kwargs):
        """Check ``X`` (errors that name it, not pymoo's assertion), then pymoo's ``Problem.evaluate``."""
        arr = self.population(X, "X")
        return super().evaluate(arr[0] if np.ndim(X) == 1 else arr, *args, **kwargs)

    def _evaluate(self, x, out, *args, **kwargs):
        K, ok, reason = self.designs(x)                  # checks the population
        stable, rho = self.stability(K)
        run = ok & stable.all(axis=1)
        B = count(K)
        J = np.full((B, self.n_obj), np.inf)
        C = np.full((B, self.n_ieq_constr), np.inf)
        flags = np.where(ok, np.where(run, "", "unstable"), reason).astype(object)
        if run.any():
            J[run], C[run] = self._goals_of(take(K, run), self._plants)
            vals = np.concatenate([J[run], C[run]], axis=1)
            bad = ~np.all(np.isfinite(vals), axis=1)
            if bad.any():
                idx = np.flatnonzero(run)[bad]
                names = [*self.objective_names, *self.constraint_names]
                for i, row in zip(idx, vals[bad], strict=True):
                    first = int(np.flatnonzero(~np.isfinite(row))[0])
                    flags[i] = f"{names[first]} returned {row[first]}"
                J[idx] = np.inf                       # flagged: the penalty p on every objective
                C[idx] = np.inf
        self.last_flags = flags
        F = penalise(J, ok, run, rho, self.penalty)
        out["F"] = F
        if self.n_ieq_constr:
            level = F.max(axis=1, keepdims=True)      # the design's penalty level where it is penalised
            pen = ~run | ~np.all(np.isfinite(C), axis=1)
            out["G"] = np.where(pen[:, None], level, np.nan_to_num(C, posinf=self.penalty))

    def __repr__(self) -> str:
        return (f"TuningProblem(family={self.family!r}, S={len(self.scenarios)}, n_var={self.n_var}, "
                f"objectives={self.objective_names}, constraints={self.constraint_names})")

    __str__ = __repr__                                  # not pymoo's table
