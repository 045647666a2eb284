"""robustctl's public docstrings name by name (issue 32 item 2): a Parameters section and a checked example.

The rule and its parser are those of ``test_docstrings.py`` (``problems``); this file applies them to
each public function and class of robustctl separately, so that a regression names the object, and
adds the public modules that no package ``__all__`` gathers: ``robustctl.validation`` and the model
modules (truck, path, pathfollow, morais2022). Names whose files other branches are documenting now
are strict expected failures (the test fails once they pass, until their entry goes).
"""

from __future__ import annotations

import importlib
import inspect

import pytest
from test_docstrings import problems, public_objects

MODULES = ("robustctl.validation", "robustctl.models.truck", "robustctl.models.path", "robustctl.models.pathfollow",
           "robustctl.models.morais2022")

# Remove an entry when its file lands with numpydoc docstrings.
PENDING: dict[str, str] = {}


def _objects() -> dict[str, object]:
    """robustctl's public functions and classes (package ``__all__`` lists, then ``MODULES``), each once."""
    out = public_objects("robustctl")
    seen = {id(obj) for obj in out.values()}
    for mod_name in MODULES:
        module = importlib.import_module(mod_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and id(obj) not in seen:
                seen.add(id(obj))
                out[f"{mod_name}.{name}"] = obj
    return out


OBJECTS = _objects()


def test_the_walk_covers_every_role_and_the_pending_names():
    for name in ("robustctl.rlqr", "robustctl.Plant", "robustctl.robust_stability",
                 "robustctl.NotStabilizableError", "robustctl.sim.LinearSimulator", "robustctl.validation.as_matrix",
                 "robustctl.models.truck.truck_plant", "robustctl.models.path.ReferencePath",
                 "robustctl.models.morais2022.get_setup"):
        assert name in OBJECTS
    assert set(PENDING) <= set(OBJECTS), "a pending name is no longer public: drop it from PENDING"


@pytest.mark.parametrize("name", [pytest.param(name, marks=[pytest.mark.xfail(reason=PENDING[name], strict=True)]
                                               if name in PENDING else []) for name in OBJECTS])
def test_public_name_has_parameters_and_a_checked_example(name):
    assert problems(OBJECTS[name]) == []
