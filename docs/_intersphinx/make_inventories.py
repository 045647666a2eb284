"""Write Sphinx inventories (objects.inv) for projects whose own one cannot be downloaded here.

CI and the development machines reach package registries only, not the
projects' documentation sites, so their ``objects.inv`` cannot be fetched.
This script builds one from the *installed* package: it walks the public
names and writes each with the URL the project's documentation uses for it
(the rules below, one function per project). Only names whose page we know
are written; a name a project does not document (e.g. pymoo's
``GeneticAlgorithm``) is left out, and the docs' ``nitpick_ignore`` says so.

Run with the docs environment (``.venv/bin/python docs/_intersphinx/make_inventories.py``)
after upgrading one of these packages. Python's and SciPy's inventories are the
projects' own, from Debian's documentation packages (see README.md here).
"""

from __future__ import annotations

import importlib
import inspect
import zlib
from pathlib import Path

HERE = Path(__file__).resolve().parent


class Inventory:
    """Entries ``name domain:role priority uri dispname`` of the version-2 format."""

    def __init__(self, project: str, version: str):
        self.project, self.version = project, version
        self.entries: dict[tuple[str, str], tuple[str, str]] = {}

    def add(self, name: str, role: str, uri: str, dispname: str = "-") -> None:
        self.entries.setdefault((name, role), (uri, dispname))

    def write(self, path: Path) -> None:
        header = (f"# Sphinx inventory version 2\n# Project: {self.project}\n# Version: {self.version}\n"
                  "# The remainder of this file is compressed using zlib.\n")
        body = "".join(f"{name} {role} 1 {uri} {disp}\n"
                       for (name, role), (uri, disp) in sorted(self.entries.items()))
        path.write_bytes(header.encode() + zlib.compress(body.encode(), 9))
        print(f"{path.name}: {len(self.entries)} entries ({self.project} {self.version})")


def _role(obj) -> str | None:
    if inspect.isclass(obj):
        return "py:exception" if issubclass(obj, BaseException) else "py:class"
    if callable(obj):
        return "py:function"
    return None


def _members(cls) -> list[tuple[str, str]]:
    """Public methods / attributes defined on ``cls`` itself (not inherited)."""
    out = []
    for name, value in vars(cls).items():
        if name.startswith("_"):
            continue
        if isinstance(value, property) or inspect.isdatadescriptor(value):
            out.append((name, "py:attribute"))
        elif callable(value) or isinstance(value, (classmethod, staticmethod)):
            out.append((name, "py:method"))
    return out


def _public(module) -> list[str]:
    names = getattr(module, "__all__", None)
    if names is None:
        names = [n for n in dir(module) if not n.startswith("_")]
    return [n for n in names if hasattr(module, n)]


# -- numpy: https://numpy.org/doc/stable/ ------------------------------------------------------
def numpy_inventory() -> Inventory:
    import numpy as np
    import numpy.linalg
    import numpy.random
    import numpy.testing
    import numpy.typing

    inv = Inventory("NumPy", np.__version__)
    gen = "reference/generated/{}.html#$"
    for name in _public(np):
        obj, full = getattr(np, name), f"numpy.{name}"
        if inspect.ismodule(obj):
            continue
        if inspect.isclass(obj) and issubclass(obj, np.generic):
            inv.add(full, "py:class", "reference/arrays.scalars.html#$")
        elif (isinstance(obj, (float, int)) and not isinstance(obj, bool)) or obj is None:
            inv.add(full, "py:data", "reference/constants.html#$")
        elif (role := _role(obj)) is not None:
            inv.add(full, role, gen.format(full))
    for cls in (np.ndarray, np.dtype):
        for member, role in _members(cls):
            inv.add(f"numpy.{cls.__name__}.{member}", role, gen.format(f"numpy.{cls.__name__}.{member}"))
    for name in _public(numpy.linalg):
        obj = getattr(numpy.linalg, name)
        if (role := _role(obj)) is not None:
            inv.add(f"numpy.linalg.{name}", role, gen.format(f"numpy.linalg.{name}"))
    for name in _public(numpy.testing):
        obj = getattr(numpy.testing, name)
        if (role := _role(obj)) is not None and not inspect.ismodule(obj):
            inv.add(f"numpy.testing.{name}", role, gen.format(f"numpy.testing.{name}"))
    # random: the Generator API (the legacy RandomState functions are left out)
    inv.add("numpy.random.Generator", "py:class", "reference/random/generator.html#$")
    inv.add("numpy.random.default_rng", "py:function", "reference/random/generator.html#$")
    for member, role in _members(np.random.Generator):
        full = f"numpy.random.Generator.{member}"
        inv.add(full, role, f"reference/random/generated/{full}.html#$")
    inv.add("numpy.random.SeedSequence", "py:class",
            "reference/random/bit_generators/generated/numpy.random.SeedSequence.html#$")
    for member in ("spawn", "generate_state"):
        full = f"numpy.random.SeedSequence.{member}"
        inv.add(full, "py:method", f"reference/random/bit_generators/generated/{full}.html#$")
    inv.add("numpy.random.PCG64", "py:class", "reference/random/bit_generators/pcg64.html#$")
    for name in numpy.typing.__all__:
        inv.add(f"numpy.typing.{name}", "py:data", "reference/typing.html#$")
    return inv


# -- python-control: https://python-control.readthedocs.io/en/<version>/ ---------------------------
def control_inventory() -> Inventory:
    import control

    inv = Inventory("Python Control Systems Library", control.__version__)
    for name in _public(control):
        obj = getattr(control, name)
        if inspect.ismodule(obj) or not getattr(obj, "__module__", "").startswith("control"):
            continue
        full = f"control.{name}"
        if (role := _role(obj)) is None:
            continue
        inv.add(full, role, f"generated/{full}.html#$")
        if inspect.isclass(obj):
            for member, mrole in _members(obj):
                inv.add(f"{full}.{member}", mrole, f"generated/{full}.html#{full}.{member}")
    return inv


# -- matplotlib: https://matplotlib.org/stable/ ---------------------------------------------
def matplotlib_inventory() -> Inventory:
    import matplotlib
    import matplotlib.axes
    import matplotlib.figure
    import matplotlib.pyplot as plt

    inv = Inventory("Matplotlib", matplotlib.__version__)
    gen = "api/_as_gen/{}.html#$"
    for cls, full in ((matplotlib.axes.Axes, "matplotlib.axes.Axes"),
                      (matplotlib.figure.Figure, "matplotlib.figure.Figure")):
        inv.add(full, "py:class", gen.format(full))
        for member, role in _members(cls):
            inv.add(f"{full}.{member}", role, gen.format(f"{full}.{member}"))
    for member, role in _members(matplotlib.figure.FigureBase):   # documented on Figure's pages
        full = f"matplotlib.figure.Figure.{member}"
        inv.add(full, role, gen.format(full))
    for member, role in _members(matplotlib.axes._base._AxesBase):  # documented on Axes' pages
        full = f"matplotlib.axes.Axes.{member}"
        inv.add(full, role, gen.format(full))
    for name in _public(plt):
        obj = getattr(plt, name)
        if inspect.isfunction(obj) and obj.__module__ == "matplotlib.pyplot":
            inv.add(f"matplotlib.pyplot.{name}", "py:function", gen.format(f"matplotlib.pyplot.{name}"))
    return inv


# -- pymoo: https://pymoo.org/ (its API reference covers the core classes only) -------------
_PYMOO_PAGES = {
    # api/model.rst documents these with autoclass
    **{f"pymoo.core.{m}.{c}": "api/model.html#$" for m, c in (
        ("algorithm", "Algorithm"), ("sampling", "Sampling"), ("selection", "Selection"),
        ("mutation", "Mutation"), ("crossover", "Crossover"), ("survival", "Survival"),
        ("termination", "Termination"), ("indicator", "Indicator"), ("population", "Population"),
        ("individual", "Individual"), ("result", "Result"))},
    # one guide page each
    "pymoo.core.problem.Problem": "problems/definition.html",
    "pymoo.core.problem.ElementwiseProblem": "problems/definition.html",
    "pymoo.core.callback.Callback": "interface/callback.html",
    "pymoo.optimize.minimize": "interface/minimize.html",
    "pymoo.algorithms.moo.nsga2.NSGA2": "algorithms/moo/nsga2.html",
    "pymoo.algorithms.moo.nsga3.NSGA3": "algorithms/moo/nsga3.html",
    "pymoo.algorithms.moo.unsga3.UNSGA3": "algorithms/moo/unsga3.html",
    "pymoo.algorithms.moo.moead.MOEAD": "algorithms/moo/moead.html",
    "pymoo.algorithms.moo.age.AGEMOEA": "algorithms/moo/age.html",
    "pymoo.algorithms.moo.age2.AGEMOEA2": "algorithms/moo/age2.html",
    "pymoo.algorithms.moo.spea2.SPEA2": "algorithms/moo/spea2.html",
    "pymoo.algorithms.moo.sms.SMSEMOA": "algorithms/moo/sms.html",
    "pymoo.algorithms.moo.rvea.RVEA": "algorithms/moo/rvea.html",
    "pymoo.algorithms.moo.ctaea.CTAEA": "algorithms/moo/ctaea.html",
    "pymoo.operators.crossover.sbx.SBX": "operators/crossover.html",
    "pymoo.operators.mutation.pm.PM": "operators/mutation.html",
    **{f"pymoo.problems.multi.zdt.ZDT{i}": "problems/multi/zdt.html" for i in range(1, 7)},
    **{f"pymoo.problems.many.dtlz.DTLZ{i}": "problems/many/dtlz.html" for i in range(1, 8)},
}


def pymoo_inventory() -> Inventory:
    import pymoo

    inv = Inventory("pymoo", pymoo.__version__)
    for full, uri in _PYMOO_PAGES.items():
        module, _, name = full.rpartition(".")
        obj = getattr(importlib.import_module(module), name)   # fails loudly if pymoo moved it
        inv.add(full, _role(obj), uri)
    return inv


# -- cvxpy: https://www.cvxpy.org/ (documents objects under their defining modules) ---------
_CVXPY = {
    "cvxpy.problems.problem.Problem": ("api_reference/cvxpy.problems.html#$", "cvxpy.Problem"),
    "cvxpy.problems.objective.Minimize": ("api_reference/cvxpy.problems.html#$", "cvxpy.Minimize"),
    "cvxpy.problems.objective.Maximize": ("api_reference/cvxpy.problems.html#$", "cvxpy.Maximize"),
    "cvxpy.expressions.variable.Variable": ("api_reference/cvxpy.expressions.html#$", "cvxpy.Variable"),
    "cvxpy.expressions.constants.parameter.Parameter": ("api_reference/cvxpy.expressions.html#$",
                                                        "cvxpy.Parameter"),
    "cvxpy.expressions.constants.constant.Constant": ("api_reference/cvxpy.expressions.html#$",
                                                      "cvxpy.Constant"),
    "cvxpy.expressions.expression.Expression": ("api_reference/cvxpy.expressions.html#$", "cvxpy.Expression"),
    "cvxpy.constraints.psd.PSD": ("api_reference/cvxpy.constraints.html#$", "cvxpy.constraints.PSD"),
}


def cvxpy_inventory() -> Inventory:
    import cvxpy as cp

    inv = Inventory("CVXPY", cp.__version__)
    for full, (uri, alias) in _CVXPY.items():
        module, _, name = full.rpartition(".")
        obj = getattr(importlib.import_module(module), name)
        inv.add(full, "py:class", uri)
        inv.add(alias, "py:class", uri.replace("$", full), alias)
        if name == "Problem":
            for member, role in _members(obj):
                target = f"{full}.{member}"
                inv.add(target, role, uri.replace("$", target))
                inv.add(f"{alias}.{member}", role, uri.replace("$", target), f"{alias}.{member}")
    return inv


# -- moocore: https://multi-objective.github.io/moocore/python/ -----------------------------
def moocore_inventory() -> Inventory:
    import moocore

    inv = Inventory("moocore", getattr(moocore, "__version__", ""))
    for name in _public(moocore):
        obj = getattr(moocore, name)
        if (role := _role(obj)) is not None:
            inv.add(f"moocore.{name}", role, f"reference/generated/moocore.{name}.html#$")
    return inv


# -- dask.distributed: https://distributed.dask.org/en/stable/ (api.rst documents these) -----
def distributed_inventory() -> Inventory:
    import distributed

    inv = Inventory("Dask.distributed", distributed.__version__)
    for name in ("Client", "Future", "LocalCluster", "SpecCluster", "as_completed"):
        obj = getattr(distributed, name)
        inv.add(f"distributed.{name}", "py:class", "api.html#$")
        if name == "Client":
            for member, role in _members(obj):
                inv.add(f"distributed.Client.{member}", role, "api.html#$")
    for name in ("wait", "fire_and_forget", "futures_of"):
        inv.add(f"distributed.{name}", "py:function", "api.html#$")
    return inv


def main() -> None:
    for name, build in (("numpy", numpy_inventory), ("control", control_inventory),
                        ("matplotlib", matplotlib_inventory), ("pymoo", pymoo_inventory),
                        ("cvxpy", cvxpy_inventory), ("moocore", moocore_inventory),
                        ("distributed", distributed_inventory)):
        build().write(HERE / f"{name}.inv")


if __name__ == "__main__":
    main()
