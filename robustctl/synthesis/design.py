"""One entry point, :func:`design`, over every design method."""

from __future__ import annotations

from importlib import import_module

from ..systems.controller import Controller
from ..systems.plant import Plant, check_plant

__all__ = ["design", "METHODS"]

# name -> "module:function"; imported lazily (cvxpy takes a second to import).
METHODS = {
    "lqr": "robustctl.synthesis.lqr:lqr",
    "rlqr": "robustctl.synthesis.rlqr:rlqr",
    "hinf": "robustctl.synthesis.hinf:hinf",
    "h2": "robustctl.synthesis.h2:h2",
    "h2hinf": "robustctl.synthesis.h2hinf:h2hinf",
    "lqg": "robustctl.synthesis.lqg:lqg",
    "rlqg": "robustctl.synthesis.lqg:rlqg",
}


def design(method: str, plant: Plant, *args, **kwargs) -> Controller:
    """Design a controller for ``plant`` with the named method.

    ``design(method, plant, ...)`` is ``robustctl.<method>(plant, ...)``: the
    remaining arguments are those of the named function, which documents them.

    Parameters
    ----------
    method : str
        The design method (case-insensitive), one of the table in the Notes.
    plant : Plant
        The plant.
    *args, **kwargs
        The arguments of the named function after ``plant``.

    Returns
    -------
    Controller
        What the named function returns (a subclass of
        :class:`~robustctl.Controller` with the method's levels).

    Raises
    ------
    ValueError
        ``method`` names no design; the named function's own errors.
    TypeError
        ``plant`` is not a :class:`~robustctl.Plant`.

    Notes
    -----
    ==========  =====================================================  ===========================
    method      function                                               controller
    ==========  =====================================================  ===========================
    "lqr"       :func:`robustctl.lqr` (LQR, Riccati)                   state feedback ``u = K x``
    "rlqr"      :func:`robustctl.rlqr` (robust LQR)                    state feedback
    "hinf"      :func:`robustctl.hinf` (H-infinity, LMI or Riccati)    state or output feedback
    "h2"        :func:`robustctl.h2` (H2, LMI)                         state or output feedback
    "h2hinf"    :func:`robustctl.h2hinf` (mixed H2/H-infinity, LMI)    state or output feedback
    "lqg"       :func:`robustctl.lqg` (LQR and Kalman filter)          output feedback
    "rlqg"      :func:`robustctl.rlqg` (robust LQR and robust filter)  output feedback
    ==========  =====================================================  ===========================

    ``hinf``, ``h2`` and ``h2hinf`` return a full-order dynamic controller
    ``u = K(z) y`` (``ctrl.Ac``, ``Bc``, ``Cc``, ``Dc``) when the plant
    declares measured outputs (``Plant(..., C=...)``), a state feedback
    otherwise or with ``feedback="state"``.

    Examples
    --------
    ``design`` calls the named function with the same arguments; an unknown
    method is named in the error:

    >>> import numpy as np
    >>> from robustctl import design, lqr
    >>> from robustctl.models.truck import truck_plant
    >>> plant = truck_plant(0.0)
    >>> ctrl = design("lqr", plant, Q=np.eye(4), R=[[1.0]])
    >>> ctrl.method, bool(np.array_equal(ctrl.K, lqr(plant, Q=np.eye(4), R=[[1.0]]).K))
    ('lqr', True)
    >>> design("lqq", plant)
    Traceback (most recent call last):
        ...
    ValueError: method must name a design: unknown design method 'lqq'; valid: h2, h2hinf, hinf, lqg, lqr, rlqg, rlqr
    """
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise ValueError(f"method must name a design: unknown design method {method!r}; "
                         f"valid: {', '.join(sorted(METHODS))}")
    check_plant(plant)
    module, func = METHODS[method.lower()].split(":")
    return getattr(import_module(module), func)(plant, *args, **kwargs)
