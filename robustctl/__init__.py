"""robustctl: robust state-feedback design (LQR, RLQR, LMI H-infinity and H2) and robust analysis.

>>> import robustctl as rc
>>> from robustctl.models.truck import truck_plant
>>> plant = truck_plant(0.0)            # the paper's truck, zero-order hold at dt = 0.1 s
>>> plant
Plant(n=4, m=1, dt=0.1)
>>> EF, EG = [[0.0, 0.0, 0.0, 0.05]], [[0.05]]
>>> ctrl = rc.design("rlqr", plant, EF, EG, mu=1e8)
>>> ctrl.K.round(3), ctrl.is_stabilizing()
(array([[-0.001, -0.007, -0.001, -1.015]]), True)
>>> rc.robust_stability(ctrl, rc.NormBounded(plant.G, EF, EG)).certified
True

Sign convention everywhere: ``u = K x``.
"""

from ._hinf import HinfController, hinf  # cvxpy itself is imported on first use
from ._margins_report import MarginsReport, margins_report
from ._rlqr import RLQRBatch, RLQRSchedule, rlqr, rlqr_gains, rlqr_schedule, rlqr_step, rlqr_step_block
from .analysis import (
    CostBound,
    CostBoundBatch,
    HinfBound,
    RobustStability,
    RobustStabilityBatch,
    WorstCase,
    guaranteed_cost,
    robust_hinf_bound,
    robust_stability,
    worst_case,
)
from .controller import Controller
from .design import design
from .errors import (
    ConvergenceError,
    InfeasibleError,
    NotStabilizableError,
    NotStabilizingError,
    RankConditionError,
    RobustCtlError,
)
from .h2 import H2Controller, h2
from .input_memory import InputMemoryFeedback
from .lqr import lqr
from .performance import lq_output
from .plant import Plant
from .regions import ConicSector, Disk, HalfPlane
from .scenarios import PlantSamples, sample_plants
from .stability import STABILITY_MARGIN, is_schur_stable, spectral_radius
from .uncertainty import NormBounded

__all__ = [
    "Plant", "NormBounded", "Controller", "design", "lqr", "rlqr", "rlqr_gains", "RLQRBatch",
    "rlqr_schedule", "RLQRSchedule", "rlqr_step", "rlqr_step_block", "hinf", "HinfController",
    "h2", "H2Controller", "Disk", "HalfPlane", "ConicSector",
    "spectral_radius", "is_schur_stable", "STABILITY_MARGIN",
    "RobustCtlError", "ConvergenceError", "RankConditionError", "InfeasibleError", "NotStabilizableError",
    "NotStabilizingError",
]
__all__ += ["sample_plants", "PlantSamples"]
__all__ += ["robust_stability", "guaranteed_cost", "robust_hinf_bound", "worst_case",
            "RobustStability", "RobustStabilityBatch", "CostBound", "CostBoundBatch", "HinfBound", "WorstCase"]
__all__ += ["lq_output", "InputMemoryFeedback", "margins_report", "MarginsReport"]
__version__ = "0.1.0"
