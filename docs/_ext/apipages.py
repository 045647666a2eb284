"""Write the API reference pages from the packages themselves.

One page per public module of ``robustctl`` and ``moo`` (every module whose
dotted name has no component starting with ``_``), listing the names of the
module's ``__all__`` (or, without ``__all__``, its public functions and
classes) in an ``autosummary`` table; autosummary then writes one page per
name. So a new module or a new name in an ``__all__`` appears in the docs
without editing them. The shared helper modules that define an ``__all__``
(``robustctl._cvx``, ``robustctl._validation``, ...) get pages too, under
"Internals", since public docstrings refer to them.

Each function or class is documented once, under its shortest public name:
``robustctl.rlqr_gains`` rather than ``robustctl.synthesis.rlqr.rlqr_gains``. The
module that defines it lists it too, as a link. Modules that share their name
with the function the package re-exports (``robustctl.design``,
``robustctl.lqr``) show their docstring without registering the module name
(a cross-reference ``robustctl.lqr`` then means the function).

Two event handlers keep the references right:

* ``missing-reference``: a full name other than the one an object is
  documented under (``moo.runner.run``, documented as ``moo.run``) links to
  its page; a docstring's short reference (``:class:`Controller```)
  means the name as seen from the module where the docstring is written. An
  object documented under its package name (``robustctl.rlqr`` from ``robustctl.synthesis.rlqr``) is rendered in
  the package's context, so a short name that Sphinx cannot find there is
  looked up in the namespace of the object's defining module and linked to
  the page of what it names (ours, or another project's through intersphinx).
  Names that do not exist there, or are private, stay unresolved (warnings).
* ``autodoc-process-bases``: "Bases:" lists a private, undocumented base
  class (for example a private mixin) as its own bases;
  ``autodoc-skip-member``: class pages include inherited members defined in
  our packages (what a public class gets from such a base), never pymoo's.

The pages are written into ``api/`` at ``config-inited``, before Sphinx
lists the sources and autosummary runs; ``api/`` is generated and not kept in
git.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import sys
from dataclasses import dataclass, field
from pathlib import Path

from sphinx.ext import intersphinx

PACKAGES = ("robustctl", "moo")
OUT_DIR = "api"
STUB_DIR = "generated"
INTERNALS = "internals"

# id(object) -> the full name it is documented under (filled by write_pages)
_DOCUMENTED: dict[int, str] = {}


@dataclass
class ModuleInfo:
    name: str
    module: object
    names: list[str]                      # documented names, in __all__ order
    submodules: list[str] = field(default_factory=list)

    @property
    def internal(self) -> bool:
        return not _public(self.name)

    @property
    def shadowed(self) -> bool:
        """The parent package's attribute of this name is not this module."""
        parent, _, leaf = self.name.rpartition(".")
        return bool(parent) and getattr(sys.modules[parent], leaf, None) is not self.module


def _public(name: str) -> bool:
    return not any(part.startswith("_") for part in name.split("."))


def _is_api_object(obj) -> bool:
    return inspect.isfunction(obj) or inspect.isclass(obj)


def public_names(module) -> list[str]:
    """``__all__`` (less submodules: they get their own page), or the public
    functions and classes the module defines."""
    if hasattr(module, "__all__"):
        return [n for n in module.__all__ if not inspect.ismodule(getattr(module, n))]
    return [n for n, obj in vars(module).items()
            if not n.startswith("_") and _is_api_object(obj)
            and getattr(obj, "__module__", None) == module.__name__]


def collect(packages=PACKAGES) -> dict[str, ModuleInfo]:
    """Every public module of ``packages`` (parents first), then the private
    modules with an ``__all__`` (the internals)."""
    public: dict[str, ModuleInfo] = {}
    internal: dict[str, ModuleInfo] = {}
    for pkg_name in packages:
        pkg = importlib.import_module(pkg_name)
        public[pkg_name] = ModuleInfo(pkg_name, pkg, public_names(pkg))
        for mod in pkgutil.walk_packages(pkg.__path__, prefix=pkg_name + "."):
            if mod.name.endswith(".__main__"):
                continue
            module = importlib.import_module(mod.name)
            if _public(mod.name):
                public[mod.name] = ModuleInfo(mod.name, module, public_names(module))
            elif hasattr(module, "__all__"):
                internal[mod.name] = ModuleInfo(mod.name, module, public_names(module))
    for name in public:
        parent = name.rpartition(".")[0]
        if parent in public:
            public[parent].submodules.append(name)
    return {**public, **internal}


def canonical_names(infos: dict[str, ModuleInfo]) -> dict[tuple[str, str], str]:
    """``(module, name) -> full name`` it is documented under.

    A function or class listed by several modules gets the shortest of its
    public names (the package's re-export), a private module's name only if
    it has no public one, and among names of equal length the one in its
    defining module (``moo.store.load_records``, not its re-export
    ``moo.experiment.load_records``); data are documented where listed.
    """
    def rank(full: str, obj) -> tuple[bool, int, bool]:
        module = full.rpartition(".")[0]
        return (not _public(module), full.count("."), module != getattr(obj, "__module__", None))

    best: dict[int, str] = {}
    for info in infos.values():
        for name in info.names:
            obj, full = getattr(info.module, name), f"{info.name}.{name}"
            if _is_api_object(obj) and (id(obj) not in best or rank(full, obj) < rank(best[id(obj)], obj)):
                best[id(obj)] = full
    out = {}
    for info in infos.values():
        for name in info.names:
            obj = getattr(info.module, name)
            out[info.name, name] = best[id(obj)] if _is_api_object(obj) else f"{info.name}.{name}"
    _DOCUMENTED.clear()
    _DOCUMENTED.update(best)
    return out


def summary(module) -> str:
    """First line of the module docstring."""
    doc = (inspect.getdoc(module) or "").strip()
    return doc.splitlines()[0] if doc else ""


def module_page(info: ModuleInfo, infos: dict[str, ModuleInfo], canonical: dict[tuple[str, str], str]) -> str:
    title = f"``{info.name}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {info.name}", "   :no-members:"]
    if info.shadowed:
        lines.append("   :no-index:")
    lines += ["", f".. currentmodule:: {info.name}", ""]
    own = [n for n in info.names if canonical[info.name, n] == f"{info.name}.{n}"]
    other = [canonical[info.name, n] for n in info.names if canonical[info.name, n] != f"{info.name}.{n}"]
    if own:
        lines += [".. rubric:: Public names", "", ".. autosummary::", f"   :toctree: {STUB_DIR}/", "",
                  *(f"   {n}" for n in own), ""]
    if other:
        lines += [".. rubric:: Defined here, documented under a shorter name", "",
                  ".. autosummary::", "", *(f"   ~{n}" for n in other), ""]
    if info.submodules:
        # links by document: an autosummary row of ``robustctl.rlqr`` would mean the function
        lines += [".. rubric:: Modules", ""]
        lines += [f"* :doc:`{m}` - {summary(infos[m].module)}" for m in info.submodules]
        lines += ["", ".. toctree::", "   :hidden:", "", *(f"   {m}" for m in info.submodules), ""]
    return "\n".join(lines)


def internals_page(infos: dict[str, ModuleInfo]) -> str:
    mods = [i.name for i in infos.values() if i.internal]
    lines = ["Internals", "=========", "",
             "Helper modules shared inside the packages (private: their names may change",
             "without deprecation). Contributors reuse them instead of writing the same",
             "check or solver call again; public docstrings refer to them.", ""]
    lines += [f"* :doc:`{m}` - {summary(infos[m].module)}" for m in mods]
    lines += ["", ".. toctree::", "   :hidden:", "", *(f"   {m}" for m in mods), ""]
    return "\n".join(lines)


def _write(path: Path, text: str) -> None:
    if not path.exists() or path.read_text() != text:   # keep mtimes: incremental builds
        path.write_text(text)


def write_pages(srcdir: str | Path, packages=PACKAGES) -> list[Path]:
    """Write ``api/<module>.rst`` for every documented module; return the files."""
    out = Path(srcdir) / OUT_DIR
    out.mkdir(exist_ok=True)
    infos = collect(packages)
    canonical = canonical_names(infos)
    written = []
    for info in infos.values():
        written.append(out / f"{info.name}.rst")
        _write(written[-1], module_page(info, infos, canonical))
    written.append(out / f"{INTERNALS}.rst")
    _write(written[-1], internals_page(infos))
    for stale in set(out.glob("*.rst")) - set(written):
        stale.unlink()
    # autosummary never removes the page of a name that left an __all__
    stubs = {f"{full}.rst" for full in canonical.values()}
    for stale in (out / STUB_DIR).glob("*.rst"):
        if stale.name not in stubs:
            stale.unlink()
    return written


# -- references ----------------------------------------------------------------------
def _documented_object(docname: str):
    """The object an ``api/generated/<name>`` page documents, or the module of an
    ``api/<module>`` page (None for other pages)."""
    prefix = f"{OUT_DIR}/{STUB_DIR}/"
    if docname.startswith(f"{OUT_DIR}/") and "/" not in docname[len(OUT_DIR) + 1:]:
        return sys.modules.get(docname[len(OUT_DIR) + 1:])
    if not docname.startswith(prefix):
        return None
    return _import_dotted(docname[len(prefix):])


def _import_dotted(full: str):
    """The object a dotted name (``moo.runner.run``) names, or None."""
    for split in range(full.count("."), 0, -1):
        parts = full.split(".")
        try:
            obj = importlib.import_module(".".join(parts[:split]))
        except ImportError:
            continue
        try:
            for attr in parts[split:]:
                obj = getattr(obj, attr)
        except AttributeError:
            return None
        return obj
    return None


def _documented_as(target: str) -> str | None:
    """The documented name of a full name of ours that is not it (``moo.runner.run`` -> ``moo.run``,
    ``moo.tuning.TuningResult.select`` -> ``moo.TuningResult.select``), or None."""
    parts = target.split(".")
    if parts[0] not in PACKAGES:
        return None
    for split in range(len(parts), 1, -1):
        obj = _import_dotted(".".join(parts[:split]))
        if obj is not None and id(obj) in _DOCUMENTED:
            return ".".join([_DOCUMENTED[id(obj)], *parts[split:]])
    return None


def _name_of(obj) -> str | None:
    """Where ``obj`` is documented: our page, or the other project's public path."""
    if id(obj) in _DOCUMENTED:
        return _DOCUMENTED[id(obj)]
    if inspect.ismodule(obj):
        return obj.__name__
    if _is_api_object(obj) and obj.__module__.split(".")[0] not in PACKAGES:
        return f"{obj.__module__}.{obj.__qualname__}"
    return None


def _missing_reference(app, env, node, contnode):
    if node.get("refdomain") != "py" or node.get("refspecific"):
        return None
    target = node["reftarget"]
    if (base := _documented_as(target)) is None:
        obj = _documented_object(node.get("refdoc", ""))
        module = obj if inspect.ismodule(obj) else sys.modules.get(getattr(obj, "__module__", "") or "")
        if module is None or not target or target.startswith("_"):
            return None
        head, *rest = target.split(".")
        if head not in vars(module):
            return None
        owner = _name_of(vars(module)[head])
        if owner is None and head in getattr(module, "__all__", ()):
            owner = f"{module.__name__}.{head}"          # data are documented where listed
        if owner is None:
            return None
        base = ".".join([owner, *rest])
    if base == target:
        return None
    py = env.domains["py"]
    new = node.deepcopy()
    new["reftarget"] = base
    new["refspecific"] = False
    ref = py.resolve_xref(env, node["refdoc"], app.builder, node["reftype"], base, new, contnode)
    ref = ref or intersphinx.missing_reference(app, env, new, contnode)
    if ref is None and any(t == base for _, t in app.config.nitpick_ignore):
        return contnode          # a known gap of the other project's documentation (conf.py)
    return ref


def _process_bases(app, name, obj, options, bases: list) -> None:
    """Replace private, undocumented bases by their own bases (recursively)."""
    i = 0
    while i < len(bases):
        base = bases[i]
        if (inspect.isclass(base) and base.__name__.startswith("_") and id(base) not in _DOCUMENTED
                and base is not object):
            bases[i:i + 1] = [b for b in base.__bases__ if b not in bases]
        else:
            i += 1


def _skip_member(app, what, name, obj, skip, options):
    """Class pages list inherited members (so a public class shows what it gets from a
    private base of ours) but only those defined in our packages, not pymoo's."""
    func = obj.fget if isinstance(obj, property) else getattr(obj, "__func__", obj)
    if what != "class" or not inspect.isroutine(func):      # data members keep autodoc's rule
        return None
    module = getattr(func, "__module__", None)
    return True if isinstance(module, str) and module.split(".")[0] not in PACKAGES else None


def _config_inited(app, config) -> None:
    written = write_pages(app.srcdir)
    # name the pages explicitly: on an incremental build Sphinx's list of sources
    # (which ``autosummary_generate = True`` reads) does not have new ones yet
    config.autosummary_generate = [str(p.relative_to(app.srcdir)) for p in written]


def setup(app):
    # at config-inited: before Sphinx lists the source files and autosummary reads them
    app.connect("config-inited", _config_inited)
    # after intersphinx's own handler (priority 500) has tried the name as written
    app.connect("missing-reference", _missing_reference, priority=900)
    app.connect("autodoc-process-bases", _process_bases)
    app.connect("autodoc-skip-member", _skip_member)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
