"""Batched closed-loop simulation of state feedback and of dynamic output feedback.

:mod:`robustctl.sim.simulator`: state feedback, model free, the compiled kernel;
:mod:`robustctl.sim.output_feedback`: a :class:`~robustctl.ControllerBatch`, ``u = K(z) (y - r)``.
"""

from .output_feedback import OutputFeedbackResult, OutputFeedbackSimulator, simulate_output_feedback
from .simulator import BACKENDS, DEFAULT_BOUND, LinearSimulator, SimulationResult, simulate_linear

__all__ = ["LinearSimulator", "SimulationResult", "simulate_linear", "BACKENDS", "DEFAULT_BOUND",
           "OutputFeedbackSimulator", "OutputFeedbackResult", "simulate_output_feedback"]
