"""Design methods: LQR, robust LQR, LQG and robust LQG, H-infinity and H2 by LMIs, and :func:`design`.

Every method returns a :class:`~robustctl.Controller`; :func:`design` names
them. The LMI syntheses import cvxpy on first use.
"""

from .design import design
from .h2 import H2Controller, h2
from .h2hinf import H2HinfController, h2hinf
from .hinf import HinfController, hinf
from .lqg import lqg, observer_controller, rlqg
from .lqr import lqr
from .performance import lq_output
from .rlqr import RLQRBatch, RLQRSchedule, rlqr, rlqr_gains, rlqr_schedule, rlqr_step, rlqr_step_block

__all__ = ["design", "lqr", "rlqr", "rlqr_gains", "RLQRBatch", "rlqr_schedule", "RLQRSchedule", "rlqr_step",
           "rlqr_step_block", "hinf", "HinfController", "h2", "H2Controller", "h2hinf", "H2HinfController", "lqg",
           "rlqg", "observer_controller", "lq_output"]
