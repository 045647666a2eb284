"""The model-free batched closed-loop simulator (:mod:`robustctl.sim.simulator`) and its compiled kernel."""

from .simulator import BACKENDS, DEFAULT_BOUND, LinearSimulator, SimulationResult, simulate_linear

__all__ = ["LinearSimulator", "SimulationResult", "simulate_linear", "BACKENDS", "DEFAULT_BOUND"]
