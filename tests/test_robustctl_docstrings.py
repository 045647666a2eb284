"""Every public function and class of robustctl has a numpydoc Parameters section and a doctest (issue 32 item 2).

The public names are those of ``robustctl.__all__`` (the role packages and the errors), of
``robustctl.sim``, ``robustctl.validation`` and of the model modules (truck, path, pathfollow,
morais2022). A name with parameters (a function's, or a class's constructor's) needs a
``Parameters`` section; every name needs an ``Examples`` section whose doctest has at least one
example (the suite runs them: ``--doctest-modules``). The sections are found the way numpydoc finds
them (a title underlined by dashes), without importing numpydoc (a docs-only dependency).
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import re

import pytest

MODULES = ("robustctl", "robustctl.sim", "robustctl.validation", "robustctl.models.truck", "robustctl.models.path",
           "robustctl.models.pathfollow", "robustctl.models.morais2022")

# Names whose files other branches are documenting now (issue 32 item 2), with the file. Remove an entry
# when its file lands with numpydoc docstrings (strict: the test fails until the entry goes).
PENDING = {
    "robustctl.design": "robustctl/synthesis/design.py (design's METHODS table) is being documented on another branch",
    "robustctl.HinfController": "robustctl/synthesis/hinf.py is being documented on another branch",
    "robustctl.H2Controller": "robustctl/synthesis/h2.py is being documented on another branch",
    "robustctl.MarginsReport": "robustctl/analysis/margins_report.py is being documented on another branch",
    "robustctl.validation.check_plant": "robustctl/systems/plant.py's argument checks are not in numpydoc form yet",
    "robustctl.validation.check_plants": "robustctl/systems/plant.py's argument checks are not in numpydoc form yet",
    "robustctl.validation.check_vertices": "robustctl/systems/plant.py's argument checks are not in numpydoc form yet",
}


def _public_objects() -> dict[str, object]:
    """``{qualified public name: function or class}``, each object once (its first public name)."""
    out: dict[str, object] = {}
    seen: set[int] = set()
    for mod_name in MODULES:
        module = importlib.import_module(mod_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and id(obj) not in seen:
                seen.add(id(obj))
                out[f"{mod_name}.{name}"] = obj
    return out


OBJECTS = _public_objects()


def _section(doc: str, title: str) -> str | None:
    """The body of the numpydoc section ``title`` (up to the next section), or None."""
    match = re.search(rf"^{re.escape(title)}\n-{{{len(title)}}}\n(.*?)(?=^\S[^\n]*\n-{{3,}}\n|\Z)", doc,
                      flags=re.MULTILINE | re.DOTALL)
    return match.group(1) if match else None


def _has_parameters(obj) -> bool:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return False
    return any(p.name != "self" for p in sig.parameters.values())


def _file(obj) -> str:
    path = inspect.getsourcefile(obj) or ""
    return path[path.rindex("robustctl/"):] if "robustctl/" in path else path


def _cases() -> list:
    marks = {name: [pytest.mark.xfail(reason=reason, strict=True)] for name, reason in PENDING.items()}
    return [pytest.param(obj, id=name, marks=marks.get(name, ())) for name, obj in OBJECTS.items()]


def test_the_walk_finds_every_role():
    names = set(OBJECTS)
    for expected in ("robustctl.rlqr", "robustctl.Plant", "robustctl.robust_stability",
                     "robustctl.NotStabilizableError", "robustctl.sim.LinearSimulator",
                     "robustctl.validation.as_matrix", "robustctl.models.truck.truck_plant",
                     "robustctl.models.morais2022.get_setup"):
        assert expected in names
    assert all(_file(obj).startswith("robustctl/") for obj in OBJECTS.values())
    assert set(PENDING) <= names, "a pending name is no longer public: drop it from PENDING"


@pytest.mark.parametrize("obj", _cases())
def test_public_name_has_parameters_and_a_doctest(obj):
    doc = inspect.getdoc(obj) or ""
    assert doc, "no docstring"
    if _has_parameters(obj):
        params = _section(doc, "Parameters")
        assert params and params.strip(), "no Parameters section"
    examples = _section(doc, "Examples")
    assert examples is not None, "no Examples section"
    assert doctest.DocTestParser().get_examples(examples), "the Examples section has no doctest (>>> lines)"


def test_section_finder_reads_numpydoc_layout():
    doc = "Summary.\n\nParameters\n----------\nx : int\n    A value.\n\nExamples\n--------\n>>> 1 + 1\n2\n"
    assert _section(doc, "Parameters").startswith("x : int")
    assert doctest.DocTestParser().get_examples(_section(doc, "Examples"))
    assert _section("Summary.\n\nNotes\n-----\nText.\n", "Parameters") is None
