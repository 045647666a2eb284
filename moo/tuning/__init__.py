"""Tune a robust controller for your own plant: the paper's method as a tool, with the full state or with sensors.

A *design family* maps a decision vector ``z`` to a controller: a state
feedback (:class:`RLQRFamily`, :class:`LQRFamily`) or a dynamic output
feedback of the plant's measured outputs (:class:`StaticOutputFeedbackFamily`,
:class:`PIDFamily`, :class:`FixedOrderFamily`, :class:`LQGFamily`,
:class:`RobustLQGFamily`), or any object of the :class:`DesignFamily`
protocol; a :class:`TuningProblem` scores every design of a population
against a set of scenario plants with goals ``f(K, plants) -> (B,)``
(objectives; constraints hold where ``<= 0``; ``K`` the gains or an
:class:`robustctl.ControllerBatch`); :func:`tune` runs a MOEA with MO-LSP on
it and returns a :class:`TuningResult`, whose :meth:`~TuningResult.select`
picks one design by the paper's Monte Carlo selection.

>>> import numpy as np, robustctl as rc
>>> from moo import tuning
>>> plant = rc.Plant([[1.1, 0.1], [0.0, 0.9]], [[0.0], [0.1]], dt=0.1)
>>> scenarios = [rc.Plant(plant.F * s, plant.G, dt=0.1) for s in (0.95, 1.0, 1.05)]
>>> def effort(K, plants):                   # any callable f(K (B, m, n), plants) -> (B,)
...     return np.abs(K).sum(axis=(1, 2))
>>> def radius(K, plants):
...     return np.max([rc.spectral_radius(p.F + p.G @ K) for p in plants], axis=0)
>>> prob = tuning.TuningProblem(tuning.LQRFamily(plant), scenarios, [effort, radius])
>>> res = tuning.tune(prob, evals=400, seed=1, pop_size=20)
>>> res.gains.shape[1:]
(1, 2)

References
----------
D. C. Morais et al., "Robust path-following control design of heavy vehicles
based on multiobjective evolutionary optimization", Expert Systems with
Applications 192 (2022) 116304.
"""

from .families import DesignFamily, FamilyControllers, FamilyGains, LQRFamily, RLQRFamily, dlqr_gains
from .goals import Bound, Goal, at_least, at_most
from .margins import DiskMargin, Margins, RobustMargin, SensitivityPeak
from .norms import H2Norm, HinfNorm, Variance
from .output_feedback import FixedOrderFamily, LQGFamily, PIDFamily, RobustLQGFamily, StaticOutputFeedbackFamily
from .poles import ControllerPoles, PoleRegion, SpectralRadius
from .problem import TuningProblem, penalise
from .response import ErrorGoal, Overshoot, PeakInput, Response, SettlingTime, StepTracking
from .selection import Selection, SelectionResult, monte_carlo_selection, select
from .tune import TuningResult, select_front, tune

__all__ = ["DesignFamily", "FamilyGains", "FamilyControllers", "RLQRFamily", "LQRFamily", "dlqr_gains",
           "StaticOutputFeedbackFamily", "PIDFamily", "FixedOrderFamily", "LQGFamily", "RobustLQGFamily",
           "TuningProblem", "penalise",
           "tune", "TuningResult", "select_front", "select", "Selection", "SelectionResult", "monte_carlo_selection",
           "Goal", "Response", "StepTracking", "ErrorGoal", "PeakInput", "SettlingTime", "Overshoot", "SpectralRadius",
           "PoleRegion", "ControllerPoles", "H2Norm", "HinfNorm", "Variance", "RobustMargin", "DiskMargin", "Margins",
           "SensitivityPeak", "Bound", "at_most", "at_least"]
