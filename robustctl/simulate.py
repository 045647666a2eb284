"""Closed-loop simulation (compatibility module: the names live in two layers).

* :mod:`robustctl.batchsim` - the model-free batched simulator:
  :class:`~robustctl.batchsim.LinearSimulator`, :func:`~robustctl.batchsim.simulate_linear`,
  :class:`~robustctl.batchsim.SimulationResult`, the divergence rule and the
  backends (compiled kernel, numpy reference).
* :mod:`robustctl.pathfollow` - the truck path-following runs of the paper on
  top of it: :class:`~robustctl.pathfollow.PathFollowing`,
  :func:`~robustctl.pathfollow.simulate`,
  :class:`~robustctl.pathfollow.PathFollowingResult`.

``from robustctl.simulate import simulate, simulate_linear, SimulationResult``
keeps working.
"""

from .batchsim import BACKENDS, DEFAULT_BOUND, LinearSimulator, SimulationResult, simulate_linear
from .pathfollow import DEFAULT_INITIAL_ERROR, PathFollowing, PathFollowingResult, simulate

__all__ = ["SimulationResult", "simulate", "simulate_linear", "DEFAULT_INITIAL_ERROR", "DEFAULT_BOUND",
           "LinearSimulator", "PathFollowing", "PathFollowingResult", "BACKENDS"]
