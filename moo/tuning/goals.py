r"""Tuning goals: the protocol and base class of every goal, bounds as constraints, and where each goal lives.

A goal is any callable ``goal(K, plants) -> (B,)`` float array: ``K`` holds
B designs that stabilise every scenario - the gains (B, m, n) of state
feedbacks ``u = K x``, or an :class:`robustctl.ControllerBatch` of dynamic
output feedbacks ``u = K(z) y`` - and ``plants`` is the scenario tuple
(:class:`robustctl.Plant`, one ``n``, ``m`` and ``dt``; with an output
feedback each carries the output model the controllers read). Smaller is
better; a constraint holds where its value is ``<= 0``. The goals of
:mod:`moo.tuning` take either kind of ``K``; they are small frozen classes
(:class:`Goal`), each batched over the B designs and the S scenarios (the
closed loops of :mod:`moo.tuning.loops` in the states ``(x, x_c)``, one
compiled simulation), each reducing the scenarios with ``over="mean"`` or
``"max"``, and each with

* ``name`` - a label for tables and plots (``name=`` overrides it);
* ``check(plants)`` - the goal's arguments against the plants (index out of
  range, reference of the wrong shape, ``Bw`` with other than ``n`` rows, a
  continuous plant for a goal that samples ...), a ``ValueError`` naming the
  argument; the tuning problem calls it once, and every call repeats it
  (cheap) so a goal is safe on its own;
* ``measure(K, plants)`` - the goal's quantity in its own sense, to which the
  bounds of :func:`at_most` and :func:`at_least` refer. It equals the goal's
  value except for the margins (:class:`~moo.tuning.RobustMargin`,
  :class:`~moo.tuning.DiskMargin`), quantities to *maximise* that are
  minimised as ``1 / margin``.

The goals, each importable from :mod:`moo.tuning`, live by concept:

=============================  =====================================================================
module                         goals
=============================  =====================================================================
:mod:`moo.tuning.response`     time domain, from one simulation per population shared by the goals
                               of a :class:`~moo.tuning.Response` or :class:`~moo.tuning.StepTracking`
                               (discrete plants): :class:`~moo.tuning.ErrorGoal` (MSE, ISE, IAE),
                               :class:`~moo.tuning.PeakInput`, :class:`~moo.tuning.SettlingTime`,
                               :class:`~moo.tuning.Overshoot`
:mod:`moo.tuning.poles`        eigenvalues: :class:`~moo.tuning.SpectralRadius`,
                               :class:`~moo.tuning.PoleRegion` (Chilali & Gahinet regions),
                               :class:`~moo.tuning.ControllerPoles`
:mod:`moo.tuning.norms`        a performance channel's :class:`~moo.tuning.H2Norm` and
                               :class:`~moo.tuning.HinfNorm`, the stationary
                               :class:`~moo.tuning.Variance` under noise
:mod:`moo.tuning.margins`      margins: :class:`~moo.tuning.DiskMargin`, :class:`~moo.tuning.Margins`
                               (disk, gain and phase), :class:`~moo.tuning.SensitivityPeak`, and the
                               certified :class:`~moo.tuning.RobustMargin` against a norm-bounded
                               uncertainty
this module                    :class:`Goal` (the base), :class:`Bound` with :func:`at_most` and
                               :func:`at_least` (constraints from any goal), :func:`check_scenarios`
=============================  =====================================================================

References
----------
P. Apkarian, D. Noll, "Nonsmooth H-infinity synthesis", IEEE TAC 51(1), 2006,
and MATLAB's ``systune`` / ``TuningGoal`` objects (goals as objects; soft goals
and hard constraints over an array of plants).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

import robustctl as rc
from robustctl.validation import check_plants, check_real

from .loops import Controllers, Loops, check_controllers, closed_loops

__all__ = ["Goal", "Bound", "at_most", "at_least", "check_scenarios", "OVER"]

#: Reductions over the scenarios a goal accepts as ``over``.
OVER = ("mean", "max")


# ---------------------------------------------------------------- shared checks
def check_scenarios(plants, name: str = "plants", *, continuous: bool = False) -> list[rc.Plant]:
    """``plants`` as a non-empty list of plants of one ``n``, ``m`` and ``dt``, discrete unless ``continuous``.

    :func:`robustctl.validation.check_plants`, with messages naming ``name[i]``;
    ``continuous=True`` accepts continuous-time plants too (all of one domain).
    """
    return check_plants(plants, name, discrete_for=None if continuous else "tuning")


def checked_loops(K, plants) -> tuple[Controllers, list[rc.Plant], Loops]:
    """The checked controllers, the plants (either domain) and their closed loops (:mod:`moo.tuning.loops`)."""
    plants = check_scenarios(plants, continuous=True)
    K = check_controllers(K, plants)
    return K, plants, closed_loops(K, plants)


def discrete(plants, what: str, hint: str = "") -> list[rc.Plant]:
    """The plants, refused by name if continuous (goals that sample)."""
    plants = check_scenarios(plants, continuous=True)
    if not plants[0].is_discrete:
        raise ValueError(f"{what} needs discrete-time plants; these are continuous{hint}")
    return plants


def reduce(values: np.ndarray, over: str) -> np.ndarray:
    """(B, S) -> (B,) by the mean or the max over the scenarios."""
    return values.mean(axis=1) if over == "mean" else values.max(axis=1)


# ---------------------------------------------------------------- base
class Goal:
    """Base of the goals of :mod:`moo.tuning` (see the module docstring for the protocol).

    Subclasses define ``name``, ``check(plants)`` and ``measure(K, plants)``;
    calling a goal returns its measure (the value to minimise). A goal need
    not derive from this class: any callable ``f(K, plants) -> (B,)`` is a
    goal for :class:`~moo.tuning.TuningProblem`. Deriving gives a ``check``
    the problem calls once, and a ``measure`` that :func:`at_most` and
    :func:`at_least` bound.

    Attributes
    ----------
    bound_label : str or None
        Class attribute: the name of :meth:`measure` in the names of bounds
        where it differs from the value's ``name`` (a margin minimised as
        ``1 / margin``: :class:`~moo.tuning.RobustMargin`'s is
        ``"robust margin"``); None, the default: ``name``.

    See Also
    --------
    moo.tuning.SpectralRadius, moo.tuning.Response, moo.tuning.H2Norm, moo.tuning.RobustMargin : goals.
    at_most, at_least : constraints from a goal.

    Examples
    --------
    The Frobenius norm of the gain as a goal:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import Goal
    >>> class GainNorm(Goal):
    ...     name = "gain norm"
    ...
    ...     def check(self, plants):
    ...         pass
    ...
    ...     def measure(self, K, plants):
    ...         return np.linalg.norm(K, axis=(1, 2))
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> GainNorm()(np.array([[[3.0, 4.0]]]), [plant])
    array([5.])
    """

    name: str
    bound_label: ClassVar[str | None] = None

    def check(self, plants) -> None:  # pragma: no cover - every goal defines it
        """``ValueError`` naming the argument that does not fit ``plants``."""
        raise NotImplementedError

    def measure(self, K, plants) -> np.ndarray:  # pragma: no cover
        """The goal's quantity per design, shape (B,)."""
        raise NotImplementedError

    def __call__(self, K, plants) -> np.ndarray:
        """The value to minimise for each design, shape (B,) (the measure)."""
        return self.measure(K, plants)

    def __repr__(self) -> str:
        over = getattr(self, "over", None)
        return f"{type(self).__name__}(name={self.name!r}" + (f", over={over!r})" if over else ")")


def set_fields(obj, **values) -> None:
    """Set the fields of a frozen dataclass ``obj`` (its ``__post_init__``'s checked values)."""
    for k, v in values.items():
        object.__setattr__(obj, k, v)


# ---------------------------------------------------------------- constraints
@dataclass(frozen=True, eq=False, repr=False)
class Bound:
    """A constraint from a goal and a bound, ``<= 0`` where it holds (:func:`at_most`, :func:`at_least`).

    The bound refers to the goal's :meth:`~Goal.measure` (for a user callable,
    its value): ``at_most``: ``measure - bound``; ``at_least``: ``bound - measure``.
    Build it with :func:`at_most` or :func:`at_least`.

    Parameters
    ----------
    goal : Goal or callable
        One of the goals of :mod:`moo.tuning` or any ``f(K, plants) -> (B,)``.
    bound : float
        The bound.
    kind : {"at_most", "at_least"}
        Which side of the bound holds.
    name : str
        Label for tables and plots.

    See Also
    --------
    at_most, at_least

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import SpectralRadius, at_most
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> K = np.array([[[-1.0, -2.0]], [[-3.0, -4.0]]])
    >>> bound = at_most(SpectralRadius(), 0.91)
    >>> bound.name
    'spectral radius <= 0.91'
    >>> np.allclose(bound(K, [plant]), SpectralRadius()(K, [plant]) - 0.91)
    True
    """

    goal: Callable[..., Any]
    bound: float
    kind: str
    name: str = field(default="")

    def check(self, plants) -> None:
        """The goal's own check, if it has one."""
        check = getattr(self.goal, "check", None)
        if callable(check):
            check(plants)

    def __call__(self, K, plants) -> np.ndarray:
        """The constraint value of each design, shape (B,); ``<= 0`` where it holds."""
        measure = self.goal.measure if isinstance(self.goal, Goal) else self.goal
        value = np.asarray(measure(K, plants), dtype=float)
        return value - self.bound if self.kind == "at_most" else self.bound - value

    def __repr__(self) -> str:
        return f"{self.kind}({self.goal!r}, {self.bound:g})"


def _goal_name(goal) -> str:
    return str(getattr(goal, "name", None) or getattr(goal, "__name__", None) or type(goal).__name__)


def _bound(goal, bound, kind: str, op: str, name: str | None) -> Bound:
    if not callable(goal):
        raise TypeError(f"goal must be a goal or a callable f(K, plants) -> (B,), got {type(goal).__name__}")
    b = check_real(bound, "bound")
    bound_label = goal.bound_label if isinstance(goal, Goal) else None
    label = bound_label or _goal_name(goal)
    return Bound(goal, b, kind, name if name is not None else f"{label} {op} {b:g}")


def at_most(goal, bound: float, *, name: str | None = None) -> Bound:
    """The constraint ``goal <= bound`` (value ``measure - bound``, ``<= 0`` where it holds).

    Parameters
    ----------
    goal : Goal or callable
        One of the goals of :mod:`moo.tuning` (its :meth:`~Goal.measure`) or any
        callable ``f(K, plants) -> (B,)``.
    bound : float
        The largest value allowed.
    name : str, optional
        Label (default e.g. ``"spectral radius <= 0.95"``).

    Returns
    -------
    Bound
        The constraint, a goal for :class:`~moo.tuning.TuningProblem`'s ``constraints``.

    Raises
    ------
    TypeError
        ``goal`` not callable, ``bound`` not a real number.

    See Also
    --------
    at_least : the other side.

    Examples
    --------
    The closed loop ``x[k+1] = 0.5 x[k]`` meets ``rho <= 0.95`` (value ``0.5 - 0.95``):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import SpectralRadius, at_most
    >>> plant = rc.Plant([[0.7]], [[1.0]], dt=0.1)
    >>> constraint = at_most(SpectralRadius(), 0.95)
    >>> constraint
    at_most(SpectralRadius(name='spectral radius', over='max'), 0.95)
    >>> constraint(np.array([[[-0.2]]]), [plant])
    array([-0.45])
    """
    return _bound(goal, bound, "at_most", "<=", name)


def at_least(goal, bound: float, *, name: str | None = None) -> Bound:
    """The constraint ``goal >= bound`` (value ``bound - measure``, ``<= 0`` where it holds).

    ``at_least(RobustMargin(unc), 1.0)`` holds for the designs certified
    robustly stable for every ``||Delta|| <= 1``.

    Parameters
    ----------
    goal : Goal or callable
        One of the goals of :mod:`moo.tuning` (its :meth:`~Goal.measure`) or any
        callable ``f(K, plants) -> (B,)``.
    bound : float
        The smallest value allowed.
    name : str, optional
        Label (default e.g. ``"robust margin >= 1"``).

    Returns
    -------
    Bound
        The constraint, a goal for :class:`~moo.tuning.TuningProblem`'s ``constraints``.

    Raises
    ------
    TypeError
        ``goal`` not callable, ``bound`` not a real number.

    See Also
    --------
    at_most : the other side.

    Examples
    --------
    Of two gains, only the second is certified for ``||Delta|| <= 0.2``
    (margins 1/9 and 3/8):

    >>> import numpy as np
    >>> import robustctl as rc
    >>> from moo.tuning import RobustMargin, at_least
    >>> plant = rc.Plant([[1.0, 0.1], [0.0, 1.0]], [[0.005], [0.1]], dt=0.1)
    >>> unc = rc.NormBounded([[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    >>> constraint = at_least(RobustMargin(unc), 0.2)
    >>> constraint.name
    'robust margin >= 0.2'
    >>> K = np.array([[[-1.0, -2.0]], [[-3.0, -4.0]]])
    >>> constraint(K, [plant]) <= 0
    array([False,  True])
    """
    return _bound(goal, bound, "at_least", ">=", name)
