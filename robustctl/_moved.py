"""The module paths that the layout by role (0.2) moved, kept importable for one release.

``import robustctl.lqr`` or ``from robustctl.batchsim import simulate_linear``
still work: each old path is a thin module in ``sys.modules`` that forwards
every attribute to the module's new home and warns once (``DeprecationWarning``)
with the new path. CHANGELOG.md lists the moves, private modules included.
"""

from __future__ import annotations

import importlib
import sys
import types
import warnings

__all__ = ["MOVED", "install"]

#: old public module path -> new one
MOVED = {
    "robustctl.plant": "robustctl.systems.plant",
    "robustctl.uncertainty": "robustctl.systems.uncertainty",
    "robustctl.regions": "robustctl.systems.regions",
    "robustctl.scenarios": "robustctl.systems.scenarios",
    "robustctl.controller": "robustctl.systems.controller",
    "robustctl.stability": "robustctl.systems.stability",
    "robustctl.input_memory": "robustctl.systems.input_memory",
    "robustctl.lqr": "robustctl.synthesis.lqr",
    "robustctl.h2": "robustctl.synthesis.h2",
    "robustctl.hinf_game": "robustctl.synthesis.hinf_game",
    "robustctl.hinf_riccati": "robustctl.synthesis.hinf_riccati",
    "robustctl.performance": "robustctl.synthesis.performance",
    "robustctl.design": "robustctl.synthesis.design",
    "robustctl.batchsim": "robustctl.sim.simulator",
    "robustctl.path": "robustctl.models.path",
    "robustctl.pathfollow": "robustctl.models.pathfollow",
}


class _MovedModule(types.ModuleType):
    """An old module path: attributes come from ``target``, with one ``DeprecationWarning``."""

    def __init__(self, name: str, target: str):
        super().__init__(name, f"Moved to {target}; this path is kept for one release.")
        self.__dict__["_target"] = target
        self.__dict__["_warned"] = False

    def __getattr__(self, attr: str):
        if attr.startswith("__"):
            raise AttributeError(attr)
        target = self.__dict__["_target"]
        if not self.__dict__["_warned"]:
            self.__dict__["_warned"] = True
            warnings.warn(f"{self.__name__} moved to {target}; import it from there or from robustctl "
                          "(the old path goes in the next release)", DeprecationWarning, stacklevel=2)
        return getattr(importlib.import_module(target), attr)


def install() -> None:
    """Put the old paths of :data:`MOVED` into ``sys.modules`` (once; new imports are lazy)."""
    for old, new in MOVED.items():
        sys.modules.setdefault(old, _MovedModule(old, new))
