"""Every public function and class of robustctl and moo has a numpydoc docstring with its parameters and an example.

The public names are the ``__all__`` of each package and of its public
subpackages (``moo.tuning``, ``moo.problems``, ``moo.algorithms``, ...). Each
function or class among them must have

* a numpydoc ``Parameters`` section when it takes parameters (a class: its
  constructor's);
* an ``Examples`` section whose doctest ends with a check: its last example
  has an expected output (the suite runs the doctests, ``--doctest-modules``).
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import pkgutil
import re

import pytest

SECTION = re.compile(r"^(?P<name>[A-Z][A-Za-z ]+)\n-{3,}\s*$", re.MULTILINE)


def public_objects(package: str) -> dict[str, object]:
    """``{qualified name: object}`` of the functions and classes in the ``__all__`` of ``package`` and of its
    public subpackages (each object once, under its first name)."""
    root = importlib.import_module(package)
    modules = [root] + [importlib.import_module(info.name)
                        for info in pkgutil.walk_packages(root.__path__, prefix=f"{package}.")
                        if info.ispkg and not any(part.startswith("_") for part in info.name.split("."))]
    seen: dict[int, str] = {}
    out: dict[str, object] = {}
    for module in modules:
        for name in getattr(module, "__all__", ()):
            obj = getattr(module, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and id(obj) not in seen:
                seen[id(obj)] = f"{module.__name__}.{name}"
                out[seen[id(obj)]] = obj
    return out


def sections(doc: str) -> dict[str, str]:
    """numpydoc sections of a cleaned docstring: ``{title: body}``."""
    heads = list(SECTION.finditer(doc))
    return {m["name"]: doc[m.end():heads[i + 1].start() if i + 1 < len(heads) else len(doc)]
            for i, m in enumerate(heads)}


def takes_parameters(obj) -> bool:
    """A function with parameters, or a class whose constructor has some (protocols have none)."""
    if inspect.isclass(obj) and getattr(obj, "_is_protocol", False):
        return False
    try:
        return bool(inspect.signature(obj).parameters)
    except (TypeError, ValueError):       # builtins without a signature
        return False


def problems(obj) -> list[str]:
    """What the docstring of ``obj`` lacks (empty: nothing)."""
    doc = inspect.getdoc(obj) or ""
    found = sections(doc)
    out = []
    if takes_parameters(obj) and "Parameters" not in found:
        out.append("no Parameters section")
    examples = doctest.DocTestParser().get_examples(found.get("Examples", ""))
    if not examples:
        out.append("no Examples doctest")
    elif not examples[-1].want.strip():
        out.append("the Examples doctest does not end with a check (its last example has no expected output)")
    return out


def test_section_parser_finds_the_numpydoc_sections():
    def documented(a):
        """Summary.

        Parameters
        ----------
        a : int

        Examples
        --------
        >>> documented(1)
        1
        """
        return a

    def bare(a):
        """Summary only.

        >>> bare(1)
        """
        return a

    assert problems(documented) == []
    assert problems(bare) == ["no Parameters section", "no Examples doctest"]
    assert takes_parameters(int.__add__) is True and takes_parameters(lambda: 0) is False


@pytest.mark.parametrize("package", ["robustctl", "moo"])
def test_public_docstrings_have_parameters_and_a_checked_example(package):
    objects = public_objects(package)
    assert objects, f"{package} has no public functions or classes in its __all__ lists"
    missing = {name: p for name, obj in objects.items() if (p := problems(obj))}
    report = "\n".join(f"  {name}: {'; '.join(p)}" for name, p in sorted(missing.items()))
    assert not missing, f"{len(missing)} of {len(objects)} public names of {package} lack docstring parts:\n{report}"
