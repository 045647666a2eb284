"""Exceptions raised by :mod:`robustctl`.

Every error is also a standard Python exception (``ValueError`` or
``RuntimeError``) so that callers who do not know this module can still catch
it the usual way.
"""

from __future__ import annotations

__all__ = ["RobustCtlError", "ConvergenceError", "RankConditionError", "InfeasibleError", "NotStabilizableError",
           "NotDetectableError", "NotStabilizingError"]


class RobustCtlError(Exception):
    """Base class of the errors this package raises on its own account.

    Bad arguments (a wrong shape, a non-number) raise plain ``ValueError`` or
    ``TypeError``; a design or an analysis that cannot be carried out for the
    problem given raises a subclass of this class, which is also a
    ``ValueError`` or a ``RuntimeError``.

    See Also
    --------
    ConvergenceError, RankConditionError, InfeasibleError : the three kinds.

    Examples
    --------
    One ``except`` clause catches every such failure of a design; the plant
    below has the unstable mode ``2`` that its input does not reach:

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[2.0, 0.0], [0.0, 0.5]], [[0.0], [1.0]], dt=0.1)
    >>> try:
    ...     rc.lqr(plant)
    ... except rc.RobustCtlError as exc:
    ...     print(type(exc).__name__)
    NotStabilizableError
    >>> int(np.linalg.matrix_rank(np.hstack([plant.F - 2.0 * np.eye(2), plant.G])))   # PBH: rank < 2
    1
    """


class ConvergenceError(RobustCtlError, RuntimeError):
    """An iteration (e.g. the steady-state RLQR recursion) did not converge.

    Raised by :func:`robustctl.lqr` when no stabilising solution of the
    Riccati equation exists and by :func:`robustctl.rlqr` when its recursion
    diverges or stops at ``max_iter``; the message says why.

    See Also
    --------
    NotStabilizableError, NotStabilizingError : its subclasses.

    Examples
    --------
    A weight ``Q`` that leaves the integrator (the eigenvalue 1 of ``F``)
    unweighted: no gain is both optimal and stabilising.

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[1.0, 0.0], [0.0, 0.5]], [[1.0], [1.0]], dt=0.1)
    >>> Q = np.diag([0.0, 1.0])
    >>> try:
    ...     rc.lqr(plant, Q=Q)
    ... except rc.ConvergenceError as exc:
    ...     print(exc)
    no stabilising solution of the discrete Riccati equation (Q^1/2, F) is not detectable ...
    >>> bool(np.allclose(Q @ [1.0, 0.0], 0.0))   # the integrator's eigenvector is not weighted
    True
    """


class RankConditionError(RobustCtlError, ValueError):
    """A rank condition a design needs does not hold (e.g. RLQR with ``mu = inf``).

    At ``mu = inf`` the robust LQR forces ``EF + EG K = 0``, which needs
    ``EG`` of full row rank (:func:`robustctl.rlqr`).

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant(np.diag([0.5, 0.6]), [[1.0], [0.0]], dt=0.1)
    >>> EF, EG = np.eye(2), [[1.0], [0.0]]
    >>> try:
    ...     rc.rlqr(plant, EF, EG, np.inf)
    ... except rc.RankConditionError as exc:
    ...     print(exc)
    mu = inf needs EG (2x1) to have full row rank 2 ...
    >>> int(np.linalg.matrix_rank(EG)) < 2
    True
    """


class InfeasibleError(RobustCtlError, ValueError):
    """A convex program (LMI) is infeasible, or the solver could not certify a solution.

    Also raised by the robust performance bounds
    (:func:`robustctl.guaranteed_cost`, :func:`robustctl.robust_hinf_bound`)
    when no bound exists because the loop is not robustly stable.

    Examples
    --------
    ``x+ = (0.5 + 0.6 Delta) x`` leaves the unit disk at ``Delta = 1``, so no
    cost bound holds for every ``|Delta| <= 1``; the small-gain value
    ``|E (z - A)^-1 H|`` peaks at ``z = 1``:

    >>> import robustctl as rc
    >>> plant = rc.Plant([[0.5]], [[1.0]], dt=0.1)
    >>> unc = rc.NormBounded([[1.0]], [[0.6]], [[0.0]])
    >>> try:
    ...     rc.guaranteed_cost((plant, [[0.0]]), unc, Q=[[1.0]], R=[[1.0]])
    ... except rc.InfeasibleError as exc:
    ...     print(exc)
    no guaranteed cost: the closed loop is not quadratically stable for every ||Delta|| <= 1 ...
    >>> 0.6 / (1.0 - 0.5) >= 1.0
    True
    """


class NotStabilizableError(ConvergenceError, InfeasibleError):
    r"""The plant is not stabilisable: some unstable mode cannot be moved by the input (PBH test).

    Raised by ``lqr``, ``rlqr``, ``hinf`` and ``h2`` before they start
    (:func:`robustctl.systems.stability.check_stabilizable`), since no gain ``u = K x``
    stabilises such a plant. It is both a :class:`ConvergenceError` (what
    ``lqr`` raised when its Riccati solver failed on such plants) and an
    :class:`InfeasibleError` (what the LMI syntheses raise when no gain
    exists), so handlers written for either keep working.

    Notes
    -----
    The Popov-Belevitch-Hautus test [1]_: ``(F, G)`` is stabilisable iff

    .. math::

        \operatorname{rank} \begin{bmatrix} F - \lambda I & G \end{bmatrix} = n

    at every eigenvalue ``lambda`` of ``F`` on or outside the unit circle
    (closed right half-plane in continuous time).

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall 1996, Thm 3.2.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant([[2.0, 0.0], [0.0, 0.5]], [[0.0], [1.0]], dt=0.1)
    >>> rc.lqr(plant)
    Traceback (most recent call last):
    ...
    robustctl.errors.NotStabilizableError: plant is not stabilisable: its mode lambda = 2+0j ...
    >>> int(np.linalg.matrix_rank(np.hstack([plant.F - 2.0 * np.eye(2), plant.G])))
    1
    """


class NotDetectableError(ConvergenceError, InfeasibleError):
    r"""The plant is not detectable: some unstable mode is not seen by the outputs ``C`` (PBH test).

    The dual of :class:`NotStabilizableError`, raised by the estimators and
    the output-feedback syntheses before they start
    (:func:`robustctl.systems.stability.check_detectable`): no observer gain
    makes the estimation error of such a plant converge.

    Notes
    -----
    ``(C, F)`` is detectable iff ``(F', C')`` is stabilisable, i.e.

    .. math::

        \operatorname{rank} \begin{bmatrix} F - \lambda I \\ C \end{bmatrix} = n

    at every eigenvalue ``lambda`` of ``F`` that is not stable [1]_.

    References
    ----------
    .. [1] K. Zhou, J. C. Doyle, K. Glover, *Robust and Optimal Control*,
       Prentice Hall 1996, Thm 3.7.

    Examples
    --------
    >>> import numpy as np
    >>> import robustctl as rc
    >>> from robustctl.systems.stability import check_detectable
    >>> plant = rc.Plant([[2.0, 0.0], [0.0, 0.5]], [[1.0], [1.0]], dt=0.1, C=[[0.0, 1.0]])
    >>> check_detectable(plant)
    Traceback (most recent call last):
    ...
    robustctl.errors.NotDetectableError: plant is not detectable: its mode lambda = 2+0j ...
    >>> int(np.linalg.matrix_rank(np.vstack([plant.F - 2.0 * np.eye(2), plant.C])))
    1
    """


class NotStabilizingError(ConvergenceError):
    """A design was computed but its gain does not stabilise the nominal plant ``F + G K``.

    Raised by :func:`robustctl.rlqr` at finite ``mu`` unless it is called with
    ``check_stability=False``; the message gives ``rho(F + G K)`` and the
    spectral radius of the RLQR's own closed loop ``L``. It is a
    :class:`ConvergenceError` (no stabilising design was found), so handlers
    written for that keep working.

    Examples
    --------
    A nearly uncontrollable unstable mode (``G`` reaches the mode ``1.2``
    with ``1e-4``): the RLQR's fictitious input stabilises its own loop,
    the gain alone does not.

    >>> import numpy as np
    >>> import robustctl as rc
    >>> plant = rc.Plant(np.diag([1.2, 0.5]), [[1e-4], [1.0]], dt=0.1)
    >>> try:
    ...     rc.rlqr(plant, [[0.1, 0.1]], [[0.1]], 1e4)
    ... except rc.NotStabilizingError as exc:
    ...     print(exc)
    the RLQR design at mu = 10000 converged but does not stabilise the nominal plant: rho(F + G K) = 1.19996 ...
    >>> ctrl = rc.rlqr(plant, [[0.1, 0.1]], [[0.1]], 1e4, check_stability=False)
    >>> bool(max(abs(np.linalg.eigvals(plant.F + plant.G @ ctrl.K))) > 1.0)
    True
    """
