"""robustctl: robust state-feedback design (LQR, RLQR, LMI H-infinity).

>>> import robustctl as rc
>>> plant = rc.Plant.from_continuous(A, B, dt=0.1)          # doctest: +SKIP
>>> ctrl = rc.design("rlqr", plant, EF, EG, mu=1e8)          # doctest: +SKIP
>>> ctrl.K, ctrl.is_stabilizing()                            # doctest: +SKIP

Sign convention everywhere: ``u = K x``.
"""

from .controller import Controller
from .design import design
from .errors import ConvergenceError, InfeasibleError, NotStabilizableError, RankConditionError, RobustCtlError
from .hinf import HinfController, hinf  # cvxpy itself is imported on first use
from .h2 import H2Controller, h2
from .regions import ConicSector, Disk, HalfPlane
from .lqr import lqr
from .plant import Plant
from .rlqr import RLQRBatch, RLQRSchedule, rlqr, rlqr_gains, rlqr_schedule
from .stability import STABILITY_MARGIN, is_schur_stable, spectral_radius
from .uncertainty import NormBounded
from .analysis import (CostBound, HinfBound, RobustStability, WorstCase, guaranteed_cost, robust_hinf_bound,
                       robust_stability, worst_case)


__all__ = [
    "Plant", "NormBounded", "Controller", "design", "lqr", "rlqr", "rlqr_gains", "RLQRBatch",
    "rlqr_schedule", "RLQRSchedule", "hinf", "HinfController",
    "h2", "H2Controller", "Disk", "HalfPlane", "ConicSector",
    "spectral_radius", "is_schur_stable", "STABILITY_MARGIN",
    "RobustCtlError", "ConvergenceError", "RankConditionError", "InfeasibleError", "NotStabilizableError",
]
__all__ += ["robust_stability", "guaranteed_cost", "robust_hinf_bound", "worst_case",
            "RobustStability", "CostBound", "HinfBound", "WorstCase"]
__version__ = "0.1.0"
