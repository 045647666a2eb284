r"""Margin goals: how far each loop of a population is from instability (loop margins, certified robust margin).

The loop goals break each design's loop on each scenario at the plant input
(or output) and read :func:`robustctl.loop_margins`, one batched call per
scenario for the whole population (state feedbacks ``(plant, K)`` or a
:class:`robustctl.ControllerBatch`); python-control's negative-feedback
convention for the loop transfer: ``L = -K(z) P(z)`` at the input,
``L = -P(z) K(z)`` at the output, ``S = (I + L)^{-1}``, ``T = I - S``.

* :class:`DiskMargin` - the disk margin ``alpha`` (minimised as
  ``1 / alpha``; :meth:`DiskMargin.measure` is ``alpha``), the worst
  scenario (``over="max"``) or their mean;
* :class:`Margins` - how far the loop is from required margins,
  ``alpha_req / alpha`` (disk) or the largest of ``GM_req / GM`` and
  ``PM_req / PM`` (classical): ``<= 1`` where they are met;
* :class:`SensitivityPeak` - ``||S||_inf`` or ``||T||_inf``, optionally
  weighted (``max_w |W(jw)| sigma_max(S(jw))``).

Robustness: :class:`RobustMargin` - the certified margin of
:func:`robustctl.robust_stability` against a :class:`robustctl.NormBounded`
uncertainty about a nominal plant, ``1 / ||E (zI - A)^-1 H||_inf`` with
``A = F + G K``, ``E = EF + EG K`` (the augmented loop for a dynamic
controller); ``at_least(RobustMargin(unc), 1.0)`` is "certified for every
``||Delta|| <= 1``".

The protocol every goal follows is in :mod:`moo.tuning.goals`.

References
----------
P. Seiler, A. Packard, P. Gahinet, "An introduction to disk margins", IEEE
Control Systems Magazine 40(5), 78-95, 2020. MATLAB's ``TuningGoal.Margins``
and ``TuningGoal.Sensitivity``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

import robustctl as rc
from robustctl.validation import check_choice, check_positive_scalar, check_real

from .goals import OVER, Goal, check_scenarios, checked_loops, reduce, set_fields
from .loops import Controllers, is_output_feedback, with_outputs

__all__ = ["DiskMargin", "Margins", "SensitivityPeak", "RobustMargin", "loop_margins_of", "required_disk_margin", "AT"]

#: Where a loop is broken.
AT = ("input", "output")


def _with_outputs(plant: rc.Plant, K: Controllers) -> rc.Plant:
    """``plant`` with the output model the controllers read (an output feedback's batch plant's, if it has none)."""
    return with_outputs(plant, K.plant) if is_output_feedback(K) else plant


def loop_margins_of(K: Controllers, plants, at: str, skew: float = 0.0, what: str = "all") -> list:
    """:func:`robustctl.loop_margins` of every design on each plant: one :class:`~robustctl.LoopMargins` per plant.

    ``K``: gains (B, m, n) (broken at the input, or at the state with
    ``at="output"``) or a :class:`robustctl.ControllerBatch` (each plant with
    the outputs the controllers read). Entries are (B,) arrays, or (B, loops).
    """
    return [rc.loop_margins(_loop(plant, K), at=at, skew=skew, what=what) for plant in plants]


def _loop(plant: rc.Plant, K: Controllers) -> Any:
    """The designs on ``plant`` as robustctl's analyses take them: ``(plant, K)`` or a ControllerBatch."""
    if is_output_feedback(K):
        return rc.ControllerBatch(_with_outputs(plant, K), K.Ac, K.Bc, K.Cc, K.Dc)
    return (plant, np.asarray(K))


def robust_margins(plant: rc.Plant, K: Controllers, unc: rc.NormBounded) -> np.ndarray:
    """``robust_stability`` margins of each design on ``plant``, shape (B,).

    ``K``: gains (B, m, n) (``(plant, K)``) or a :class:`robustctl.ControllerBatch`
    (its loops through ``plant``'s outputs, the augmented uncertainty). One
    batched call of :func:`robustctl.robust_stability` (margins only: the
    certificates of a stack are computed on request). Unstable loops get 0,
    a design the analysis cannot answer NaN (the tuning problem penalises it).
    """
    return np.array(rc.robust_stability(_loop(plant, K), unc).margin, dtype=float)


def required_disk_margin(gain_db: float | None, phase_deg: float | None) -> float:
    r"""The balanced disk margin (skew 0) that guarantees ``+-gain_db`` and ``+-phase_deg`` at once.

    The inverse of :func:`robustctl.disk_ranges` for ``skew = 0``: the disk of :math:`\alpha` covers the gains
    :math:`[\frac{2 - \alpha}{2 + \alpha}, \frac{2 + \alpha}{2 - \alpha}]` and the
    phases :math:`\pm 2 \arctan(\alpha / 2)`, so

    .. math::

        \alpha = \max\Big(2 \frac{g - 1}{g + 1},\ 2 \tan\frac{\phi}{2}\Big),
        \qquad g = 10^{\text{gain\_db} / 20} .

    Parameters
    ----------
    gain_db : float, optional
        Required gain margin in dB (> 0).
    phase_deg : float, optional
        Required phase margin in degrees (in (0, 180)).

    Returns
    -------
    float

    Raises
    ------
    ValueError
        Neither given, or one out of range.

    Examples
    --------
    MATLAB's ``TuningGoal.Margins(..., 6, 45)``: the disk margin 0.8284 gives
    45 degrees and more than 6 dB:

    >>> from moo.tuning.margins import required_disk_margin
    >>> round(required_disk_margin(6.0, 45.0), 4), round(required_disk_margin(6.0, None), 4)
    (0.8284, 0.6646)
    """
    if gain_db is None and phase_deg is None:
        raise ValueError("give gain_db, phase_deg or both")
    alpha = 0.0
    if gain_db is not None:
        g = 10.0 ** (check_positive_scalar(gain_db, "gain_db") / 20.0)
        alpha = max(alpha, 2.0 * (g - 1.0) / (g + 1.0))
    if phase_deg is not None:
        phi = check_positive_scalar(phase_deg, "phase_deg")
        if phi >= 180.0:
            raise ValueError(f"phase_deg must be in (0, 180) degrees, got {phi}")
        alpha = max(alpha, 2.0 * np.tan(np.radians(phi) / 2.0))
    return float(alpha)


class _LoopGoal(Goal):
    """What the loop goals share: the plants' check (either time domain)."""

    def check(self, plants) -> None:
        """Only the plants themselves (either time domain)."""
        check_scenarios(plants, continuous=True)


@dataclass(frozen=True, eq=False, repr=False)
class DiskMargin(_LoopGoal):
    r"""The disk margin of the loop (a quantity to maximise), the worst (default) or mean over the scenarios.

    :meth:`measure` is ``alpha`` (bounds refer to it:
    ``at_least(DiskMargin(), 0.5)``); as an objective the goal is minimised
    as ``1 / alpha``. For several loops ``alpha`` is the simultaneous
    margin (a lower bound, :func:`robustctl.loop_margins`), or the smallest
    loop-at-a-time margin with ``each=True``.

    Parameters
    ----------
    at : {"input", "output"}
        Where the loop is broken (default the plant input).
    skew : float
        The disk's skew :math:`\sigma` (0: balanced).
    each : bool
        Loop-at-a-time margins (the smallest) instead of the simultaneous one.
    over : {"mean", "max"}
        Reduction of ``1 / alpha`` over the scenarios (default the max: the
        worst scenario).
    name : str, optional
        Label (default ``"1/disk margin"``).

    Raises
    ------
    ValueError
        ``at`` or ``over`` not one of the choices, a non-finite ``skew``.

    See Also
    --------
    Margins : required gain and phase margins.
    robustctl.loop_margins : the analysis.

    Notes
    -----
    .. math::

        \alpha = \frac{1}{\sup_\omega \mu\big(S(e^{j\omega}) + \frac{\sigma - 1}{2} I\big)},

    with :math:`\mu = |\cdot|` for one loop [1]_.

    References
    ----------
    .. [1] P. Seiler, A. Packard, P. Gahinet, "An introduction to disk
       margins", IEEE Control Systems Magazine 40(5), 78-95, 2020.

    Examples
    --------
    Against python-control's ``disk_margins`` at the frequency of the peak:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import DiskMargin
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-3.0, -2.5]]])
    >>> alpha = DiskMargin().measure(K, [plant])
    >>> w = rc.loop_margins((plant, K[0])).alpha_freq
    >>> dm = control.disk_margins(control.ss(plant.F, plant.G, -K[0], 0, 0.1), np.array([w]))[0]
    >>> bool(np.isclose(alpha[0], dm, rtol=1e-8))
    True
    """

    at: str = "input"
    skew: float = 0.0
    each: bool = False
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        set_fields(self, at=check_choice(self.at, "at", AT), skew=check_real(self.skew, "skew"),
             over=check_choice(self.over, "over", OVER), each=bool(self.each),
             name=self.name or "1/disk margin")

    def _inverse(self, K, plants) -> np.ndarray:
        K, plants, _ = checked_loops(K, plants)
        per = []
        for m in loop_margins_of(K, plants, self.at, self.skew, what="disk"):
            a = np.asarray(m.alpha_loops if self.each else m.alpha, dtype=float)
            per.append(a.min(axis=-1) if a.ndim == 2 else a)
        with np.errstate(divide="ignore"):
            return 1.0 / np.stack(per, axis=1)                          # (B, S)

    def measure(self, K, plants) -> np.ndarray:
        """The disk margin of each design (the worst or mean scenario), shape (B,)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self(K, plants)

    def __call__(self, K, plants) -> np.ndarray:
        """``1 / alpha`` of each design (to minimise), shape (B,)."""
        return reduce(self._inverse(K, plants), self.over)


@dataclass(frozen=True, eq=False, repr=False)
class Margins(_LoopGoal):
    r"""How far the loop is from required gain and phase margins: ``<= 1`` where they are met.

    MATLAB's ``TuningGoal.Margins``. ``kind="disk"`` (default): the balanced
    disk margin ``alpha`` against the one that guarantees both requirements
    at once (:func:`required_disk_margin`), value ``alpha_req / alpha``.
    ``kind="classical"``: the classical margins of every loop (others closed)
    against the requirements, value ``max(GM_req / GM, PM_req / PM)`` in dB
    and degrees over the loops. The constraint is ``at_most(Margins(...), 1)``.

    Parameters
    ----------
    gain_db : float, optional
        Required gain margin in dB (default 6 when ``phase_deg`` is not given either).
    phase_deg : float, optional
        Required phase margin in degrees.
    at : {"input", "output"}
        Where the loop is broken.
    kind : {"disk", "classical"}
        Disk-based (simultaneous gain and phase variations) or classical margins.
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label (default e.g. ``"margins (6 dB, 45 deg)"``).

    Raises
    ------
    ValueError
        Requirements out of range, an unknown ``at``, ``kind`` or ``over``.

    See Also
    --------
    DiskMargin, robustctl.loop_margins

    Notes
    -----
    .. math::

        v_{disk} = \frac{\alpha_{req}}{\alpha}, \qquad
        v_{classical} = \max_i \max\Big(\frac{GM_{req}}{|20 \log_{10} GM_i|},\
        \frac{PM_{req}}{PM_i}\Big)

    (``inf`` where a margin is not positive).

    Examples
    --------
    The classical value against python-control's ``stability_margins``:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import Margins
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-3.0, -2.5]]])
    >>> value = Margins(gain_db=6.0, phase_deg=30.0, kind="classical")(K, [plant])
    >>> gm, pm = control.stability_margins(control.ss(plant.F, plant.G, -K[0], 0, 0.1))[:2]
    >>> bool(np.isclose(value[0], max(6.0 / abs(20 * np.log10(gm)), 30.0 / pm), rtol=1e-8))
    True
    """

    gain_db: float | None = None
    phase_deg: float | None = None
    at: str = "input"
    kind: str = "disk"
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        gain = 6.0 if self.gain_db is None and self.phase_deg is None else self.gain_db
        required_disk_margin(gain, self.phase_deg)                             # checks the requirements
        label = ", ".join(part for part in (None if gain is None else f"{gain:g} dB",
                                            None if self.phase_deg is None else f"{self.phase_deg:g} deg") if part)
        set_fields(self, gain_db=gain, at=check_choice(self.at, "at", AT),
             kind=check_choice(self.kind, "kind", ("disk", "classical")),
             over=check_choice(self.over, "over", OVER), name=self.name or f"margins ({label})")

    def __call__(self, K, plants) -> np.ndarray:
        """The requirement ratio of each design, shape (B,) (``<= 1``: met)."""
        return self.measure(K, plants)

    def measure(self, K, plants) -> np.ndarray:
        """The requirement ratio of each design, shape (B,) (``<= 1``: met)."""
        K, plants, _ = checked_loops(K, plants)
        per = []
        with np.errstate(divide="ignore", invalid="ignore"):
            for m in loop_margins_of(K, plants, self.at, what="disk" if self.kind == "disk" else "all"):
                if self.kind == "disk":
                    per.append(required_disk_margin(self.gain_db, self.phase_deg) / np.asarray(m.alpha, float))
                    continue
                ratio = np.zeros(np.shape(m.gain_margin))
                if self.gain_db is not None:                     # a margin below 1 (gain decrease) counts alike
                    gm_db = np.abs(20.0 * np.log10(np.asarray(m.gain_margin, dtype=float)))
                    ratio = np.maximum(ratio, np.where(gm_db > 0, self.gain_db / gm_db, np.inf))
                if self.phase_deg is not None:
                    pm = np.asarray(m.phase_margin, dtype=float)
                    ratio = np.maximum(ratio, np.where(pm > 0, self.phase_deg / pm, np.inf))
                per.append(ratio.max(axis=-1) if ratio.ndim == 2 else ratio)
        return reduce(np.stack(per, axis=1), self.over)


@dataclass(frozen=True, eq=False, repr=False)
class SensitivityPeak(_LoopGoal):
    r"""Peak of the sensitivity ``S`` or the complementary sensitivity ``T``, optionally weighted.

    Without a weight: :math:`\|S\|_\infty` or :math:`\|T\|_\infty` of
    :func:`robustctl.loop_margins` (level sets, exact). With a weight
    ``W`` (a stable SISO python-control system of the plants' time
    domain): :math:`\max_\omega |W(j\omega)|\, \bar\sigma(S(j\omega))`, on a
    logarithmic sweep of ``points`` frequencies refined by golden-section
    search at its largest value (an estimate from below, accurate to about
    1e-9 in frequency at the peak it finds).

    Parameters
    ----------
    which : {"S", "T"}
        The sensitivity (default ``S``: ``1 / ||S||`` is the distance of the
        Nyquist plot to -1) or the complementary sensitivity.
    at : {"input", "output"}
        Where the loop is broken.
    weight : python-control system, optional
        A stable SISO frequency weight.
    points : int
        Sweep size for a weighted peak (default 400).
    over : {"mean", "max"}
        Reduction over the scenarios (default the max).
    name : str, optional
        Label (default ``"S peak"`` or ``"T peak"``).

    Raises
    ------
    TypeError, ValueError
        An unknown ``which``, ``at`` or ``over``; a weight that is not a
        stable SISO python-control system (or of another time domain, when
        checked against the plants).

    See Also
    --------
    DiskMargin, robustctl.loop_margins

    Notes
    -----
    :math:`S = (I + L)^{-1}`, :math:`T = I - S`, :math:`L = -K P` at the input.

    Examples
    --------
    ``1 / ||S||`` is python-control's stability margin ``sm``:

    >>> import numpy as np, control
    >>> import robustctl as rc
    >>> from moo.tuning import SensitivityPeak
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-3.0, -2.5]]])
    >>> peak = SensitivityPeak()(K, [plant])
    >>> sm = control.stability_margins(control.ss(plant.F, plant.G, -K[0], 0, 0.1))[2]
    >>> bool(np.isclose(peak[0], 1 / sm, rtol=1e-6))
    True
    """

    which: str = "S"
    at: str = "input"
    weight: Any = None
    points: int = 400
    over: str = "max"
    name: str = ""

    def __post_init__(self):
        which = check_choice(self.which, "which", ("S", "T"))
        weight = None
        if self.weight is not None:
            import control

            try:
                weight = control.ss(self.weight)
            except (TypeError, ValueError):
                raise TypeError(f"weight must be a python-control system, got {type(self.weight).__name__}") \
                    from None
            if weight.ninputs != 1 or weight.noutputs != 1:
                raise ValueError(f"weight must be SISO, got {weight.noutputs} outputs and {weight.ninputs} inputs")
            poles = weight.poles()
            if (np.abs(poles) >= 1).any() if weight.isdtime(strict=True) else (poles.real >= 0).any():
                raise ValueError("weight must be stable")
        points = int(self.points)
        if points < 16:
            raise ValueError(f"points must be >= 16, got {self.points}")
        set_fields(self, which=which, at=check_choice(self.at, "at", AT), weight=weight, points=points,
             over=check_choice(self.over, "over", OVER), name=self.name or f"{which} peak")

    def check(self, plants) -> None:
        """The weight's time domain must be the plants'."""
        plants = check_scenarios(plants, continuous=True)
        if self.weight is not None and bool(self.weight.isdtime(strict=True)) != plants[0].is_discrete:
            raise ValueError("weight must be of the plants' time domain (discrete or continuous)")

    def measure(self, K, plants) -> np.ndarray:
        """The (weighted) peak of each design, shape (B,)."""
        self.check(plants)
        K, plants, loops = checked_loops(K, plants)
        if self.weight is None:
            per = [np.asarray(m.S_peak if self.which == "S" else m.T_peak, dtype=float)
                   for m in loop_margins_of(K, plants, self.at)]
            return reduce(np.stack(per, axis=1), self.over)
        return reduce(_weighted_peak(loops, plants[0].dt, self), self.over)


def _sensitivity_at(loops, z: np.ndarray, which: str) -> np.ndarray:
    """``sigma_max`` of ``S`` or ``T`` at the input, (B, S, F), at points ``z`` broadcast to (B, S, F)."""
    A, Bv, Ku, E = loops.A, loops.Bv, loops.Ku, loops.E                 # v added at u -> u: S at the input
    N = A.shape[-1]
    M = np.asarray(z)[..., None, None] * np.eye(N) - A[:, :, None]
    X = np.linalg.solve(M, np.broadcast_to(Bv[:, :, None], (*M.shape[:3], *Bv.shape[2:])).astype(complex))
    S = Ku[:, :, None] @ X + E[:, :, None]
    if which == "T":
        S = np.eye(S.shape[-1]) - S
    return np.linalg.svd(S, compute_uv=False)[..., 0]


def _weight_at(weight, z: np.ndarray) -> np.ndarray:
    """``|W(z)|`` of a SISO state-space weight at any array of points ``z``."""
    A, B, C, D = (np.asarray(M, dtype=float) for M in (weight.A, weight.B, weight.C, weight.D))
    n = A.shape[0]
    if n == 0:
        return np.full(np.shape(z), abs(float(D[0, 0])))
    X = np.linalg.solve(np.asarray(z)[..., None, None] * np.eye(n) - A, np.broadcast_to(B, (*np.shape(z), n, 1))
                        .astype(complex))
    return np.abs((C @ X)[..., 0, 0] + D[0, 0])


def _weighted_peak(loops, dt: float | None, goal: SensitivityPeak) -> np.ndarray:
    """``max_w |W| sigma_max`` (B, S): a log sweep, then golden-section refinement at each largest value."""
    if goal.at != "input":
        raise NotImplementedError("weighted peaks are computed at the plant input; use at='input'")
    if dt:
        top = np.pi / dt
    else:
        top = 10.0 * max(1.0, float(np.abs(np.linalg.eigvals(loops.A)).max()))
    w = np.logspace(np.log10(top) - 6.0, np.log10(top), goal.points)

    def value(freqs: np.ndarray) -> np.ndarray:
        zs = np.exp(1j * freqs * dt) if dt else 1j * freqs
        return _sensitivity_at(loops, zs, goal.which) * _weight_at(goal.weight, zs)

    v = value(w)                                                      # (B, S, F)
    k = np.argmax(v, axis=-1)
    best = v.max(axis=-1)
    a, b = np.log(w[np.maximum(k - 1, 0)]), np.log(w[np.minimum(k + 1, w.size - 1)])
    g = (np.sqrt(5.0) - 1.0) / 2.0
    for _ in range(60):                                               # golden section in log frequency, per loop
        c, d = b - g * (b - a), a + g * (b - a)
        fc, fd = value(np.exp(c)[..., None])[..., 0], value(np.exp(d)[..., None])[..., 0]
        left = fc > fd
        b, a = np.where(left, d, b), np.where(left, a, c)
        best = np.maximum(best, np.maximum(fc, fd))
    return best


@dataclass(frozen=True, eq=False, repr=False)
class RobustMargin(Goal):
    r"""The certified robust-stability margin against a norm-bounded uncertainty (a quantity to maximise).

    The margin of :func:`robustctl.robust_stability` ``((nominal, K),
    uncertainty)``: the loop is quadratically stable for every
    ``||Delta|| <= margin`` (``inf`` if the uncertainty does not reach the
    loop). :meth:`measure` returns the margin, to which bounds refer
    (``at_least(RobustMargin(unc), 1.0)``: certified); as an objective the
    goal is minimised as ``1 / margin`` (the small-gain norm; 0 for an
    unreachable loop).

    Parameters
    ----------
    uncertainty : robustctl.NormBounded
        E.g. :meth:`robustctl.NormBounded.from_plants` of the scenarios.
    nominal : robustctl.Plant, optional
        The plant the uncertainty is about (default: the first scenario).
    name : str, optional
        Label for tables and plots.

    Raises
    ------
    TypeError
        ``uncertainty`` not a :class:`robustctl.NormBounded`, ``nominal`` not
        a :class:`robustctl.Plant`.
    ValueError
        (When checked against the plants.) An uncertainty or a nominal plant
        whose sizes do not fit the plants.

    See Also
    --------
    robustctl.robust_stability : the analysis it calls (batched over the designs).
    at_least : the constraint form.
    HinfNorm : the norm of a performance channel.

    Notes
    -----
    For :math:`[\delta F\ \delta G] = H \Delta [E_F\ E_G]` about the nominal
    plant, with :math:`A = F + G K`, :math:`E = E_F + E_G K`,

    .. math::

        \text{margin}(K) = \frac{1}{\|E (zI - A)^{-1} H\|_\infty},

    and the small-gain theorem certifies stability for every
    :math:`\|\Delta\| < \text{margin}` [1]_.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall, 1996, Ch. 9.

    Examples
    --------
    An uncertain entry ``F[1, 0]`` (``H = e_2``, ``E_F = e_1^T``): the
    margin is the inverse of the ``H -> E`` gain, 9 for this gain:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import RobustMargin
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> goal = RobustMargin(rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]]))
    >>> K = np.array([[[-1.0, -2.0]]])
    >>> goal.measure(K, [plant]), goal(K, [plant])
    (array([0.11111111]), array([9.]))
    """

    uncertainty: rc.NormBounded
    nominal: rc.Plant | None = None
    name: str = "1/robust margin"
    bound_label = "robust margin"

    def __post_init__(self):
        if not isinstance(self.uncertainty, rc.NormBounded):
            raise TypeError(f"uncertainty must be a robustctl.NormBounded, got {type(self.uncertainty).__name__}")
        if self.nominal is not None and not isinstance(self.nominal, rc.Plant):
            raise TypeError(f"nominal must be a robustctl.Plant or None, got {type(self.nominal).__name__}")

    def _plant(self, plants) -> rc.Plant:
        plants = check_scenarios(plants, continuous=True)
        nominal = plants[0] if self.nominal is None else self.nominal
        try:
            self.uncertainty.check_plant(nominal)
        except ValueError as exc:
            raise ValueError(f"uncertainty does not fit the plants: {exc}") from None
        if (nominal.n, nominal.m, nominal.dt) != (plants[0].n, plants[0].m, plants[0].dt):
            raise ValueError(f"nominal must have n={plants[0].n}, m={plants[0].m}, dt={plants[0].dt} like the "
                             f"plants, got n={nominal.n}, m={nominal.m}, dt={nominal.dt}")
        return nominal

    def check(self, plants) -> None:
        """``ValueError`` if the uncertainty or the nominal plant does not fit ``plants``."""
        self._plant(plants)

    def measure(self, K, plants) -> np.ndarray:
        """The margin of each design, shape (B,) (to maximise)."""
        nominal = self._plant(plants)
        K, plants, _ = checked_loops(K, plants)
        return robust_margins(nominal, K, self.uncertainty)

    def __call__(self, K, plants) -> np.ndarray:
        """``1 / margin`` of each design (to minimise)."""
        with np.errstate(divide="ignore"):
            return 1.0 / self.measure(K, plants)

    def __repr__(self) -> str:
        return f"RobustMargin({self.uncertainty!r}, name={self.name!r})"
