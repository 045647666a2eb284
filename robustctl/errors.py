"""Exceptions raised by :mod:`robustctl`.

Every error is also a standard Python exception (``ValueError`` or
``RuntimeError``) so that callers who do not know this module can still catch
it the usual way.
"""

from __future__ import annotations

__all__ = ["RobustCtlError", "ConvergenceError", "RankConditionError", "InfeasibleError", "NotStabilizableError",
           "NotDetectableError", "NotStabilizingError"]


class RobustCtlError(Exception):
    """Base class of the errors this package raises on its own account."""


class ConvergenceError(RobustCtlError, RuntimeError):
    """An iteration (e.g. the steady-state RLQR recursion) did not converge."""


class RankConditionError(RobustCtlError, ValueError):
    """A rank condition a design needs does not hold (e.g. RLQR with ``mu = inf``)."""


class InfeasibleError(RobustCtlError, ValueError):
    """A convex program (LMI) is infeasible, or the solver could not certify a solution."""


class NotStabilizableError(ConvergenceError, InfeasibleError):
    """The plant is not stabilisable: some unstable mode cannot be moved by the input (PBH test).

    Raised by ``lqr``, ``rlqr``, ``hinf`` and ``h2`` before they start
    (:func:`robustctl.systems.stability.check_stabilizable`), since no gain ``u = K x``
    stabilises such a plant. It is both a :class:`ConvergenceError` (what
    ``lqr`` raised when its Riccati solver failed on such plants) and an
    :class:`InfeasibleError` (what the LMI syntheses raise when no gain
    exists), so handlers written for either keep working.
    """


class NotDetectableError(ConvergenceError, InfeasibleError):
    """The plant is not detectable: some unstable mode is not seen by the outputs ``C`` (PBH test).

    The dual of :class:`NotStabilizableError`, raised by the estimators and
    the output-feedback syntheses before they start
    (:func:`robustctl.systems.stability.check_detectable`): no observer gain
    makes the estimation error of such a plant converge.
    """


class NotStabilizingError(ConvergenceError):
    """A design was computed but its gain does not stabilise the nominal plant ``F + G K``.

    Raised by :func:`robustctl.rlqr` at finite ``mu`` unless it is called with
    ``check_stability=False``; the message gives ``rho(F + G K)`` and the
    spectral radius of the RLQR's own closed loop ``L``. It is a
    :class:`ConvergenceError` (no stabilising design was found), so handlers
    written for that keep working.
    """
