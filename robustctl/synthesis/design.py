"""One entry point, :func:`design`, over every state-feedback design method."""

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
    "lqg": "robustctl.synthesis.lqg:lqg",
    "rlqg": "robustctl.synthesis.lqg:rlqg",
}


def design(method: str, plant: Plant, *args, **kwargs) -> Controller:
    """Design a state feedback ``u = K x`` for ``plant`` with the named method.

    ``design(method, plant, ...)`` is ``robustctl.<method>(plant, ...)``: the
    remaining arguments are those of the named function (:func:`robustctl.lqr`,
    :func:`robustctl.rlqr`, :func:`robustctl.hinf`), which documents them.

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
    ValueError: method must name a design: unknown design method 'lqq'; valid: h2, hinf, lqg, lqr, rlqg, rlqr
    """
    if not isinstance(method, str) or method.lower() not in METHODS:
        raise ValueError(f"method must name a design: unknown design method {method!r}; "
                         f"valid: {', '.join(sorted(METHODS))}")
    check_plant(plant)
    module, func = METHODS[method.lower()].split(":")
    return getattr(import_module(module), func)(plant, *args, **kwargs)
