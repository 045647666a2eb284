"""The package layout by role (docs/architecture.rst): imports point down, no cycles, old paths still work.

An AST walk over every module of ``robustctl`` and ``moo`` collects its
imports of our own modules (absolute and relative, also inside functions),
then checks the layer order of ``../shared/DESIGN.md`` and that the module
graph has no cycle.
"""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# robustctl's roles, from the top; a role imports only roles below it (the base: errors, validation, _cvx, ...).
ROLES = ["models", "sim", "analysis", "synthesis", "estimation", "systems"]
FACADE = {"robustctl", "robustctl.validation", "robustctl._moved"}   # the package's own entry points


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """The modules of ours that ``path`` imports (``from . import x`` counts as ``pkg.x`` if that is a module)."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            modules = {f"{target}.{a.name}" for a in node.names if _exists(f"{target}.{a.name}")}
            found |= modules
            if len(modules) < len(node.names):   # a name defined in target itself (its __init__ for a package)
                found.add(target)
    return {m for m in found if m.split(".")[0] in ("robustctl", "moo") and _exists(m)}


def _exists(module: str) -> bool:
    base = ROOT.joinpath(*module.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


GRAPH = {_module_name(p): _imports(p) for pkg in ("robustctl", "moo") for p in sorted((ROOT / pkg).rglob("*.py"))}


def _role(module: str) -> str:
    parts = module.split(".")
    if module in FACADE:
        return "facade"
    return parts[1] if len(parts) > 1 and parts[1] in ROLES else "base"


def test_every_module_is_in_a_role_package_or_the_base():
    base = sorted(m for m in GRAPH if m.startswith("robustctl.") and _role(m) == "base")
    assert base == ["robustctl._cvx", "robustctl._jit", "robustctl._kkt", "robustctl._validation", "robustctl.errors"]


def test_robustctl_imports_point_down():
    rank = {role: i for i, role in enumerate([*ROLES, "base"])}
    wrong = []
    for module, imported in GRAPH.items():
        if not module.startswith("robustctl") or module in FACADE:
            continue
        for target in imported:
            if target.startswith("moo"):
                wrong.append(f"{module} -> {target} (robustctl never imports moo)")
            elif target in FACADE or (_role(target) != _role(module) and rank[_role(target)] < rank[_role(module)]):
                wrong.append(f"{module} ({_role(module)}) -> {target} ({_role(target)})")
    assert not wrong, "imports against the layer order:\n" + "\n".join(sorted(wrong))


def test_moo_uses_only_robustctls_public_api():
    private = sorted(f"{m} -> {t}" for m, imported in GRAPH.items() if m.startswith("moo")
                     for t in imported if t.startswith("robustctl") and any(p.startswith("_") for p in t.split(".")))
    assert not private


def test_no_import_cycles():
    # an edge to a package means its __init__, which the graph holds under the package name
    state: dict[str, int] = {}
    cycles = []

    def visit(node, stack):
        state[node] = 1
        for nxt in sorted(GRAPH.get(node, ())):
            if nxt == node or nxt == node.rpartition(".")[0] or node == nxt.rpartition(".")[0]:
                continue  # a package and its own modules: __init__ re-exports (Python resolves those)
            if state.get(nxt) == 1:
                cycles.append(" -> ".join([*stack[stack.index(nxt):], nxt]))
            elif nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = 2

    for node in sorted(GRAPH):
        if node not in state:
            visit(node, [node])
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_the_architecture_page_lists_every_role_package():
    page = (ROOT / "docs" / "architecture.rst").read_text()
    for role in ROLES:
        assert f"robustctl/{role}/" in page
    for module in sorted(m for m in GRAPH if m.startswith("robustctl.") and m.count(".") == 2
                         and not m.split(".")[-1].startswith("_")):
        role, leaf = module.split(".")[1:]
        section = page.split(f"``robustctl/{role}/``", 1)[1].split("\n\n``", 1)[0]
        assert f"``{leaf}.py``" in section, f"{module} missing from the page's {role} section"


@pytest.mark.parametrize("old", ["robustctl.lqr", "robustctl.batchsim", "robustctl.plant", "robustctl.pathfollow",
                                 "robustctl.hinf_riccati", "robustctl.stability"])
def test_old_module_paths_work_and_warn_once(old):
    import robustctl
    from robustctl._moved import MOVED

    new = importlib.import_module(MOVED[old])
    name = next(n for n in getattr(new, "__all__", dir(new)) if not n.startswith("_"))
    code = (f"import warnings; warnings.simplefilter('always')\n"
            f"from {old} import {name} as a\nfrom {old} import {name} as b\n"
            f"import sys\nassert a is b is getattr(sys.modules[{MOVED[old]!r}], {name!r})")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stderr.count("DeprecationWarning") == 1 and MOVED[old] in out.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        importlib.import_module(old)
    assert callable(robustctl.lqr) and callable(robustctl.design)   # the functions, never shadowed by a module
