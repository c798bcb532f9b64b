"""The package layout (issues 10, 29): the library stands apart from the studies, the reference never
reaches the Rust core, studies use only public names, no import cycles."""

import ast
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ukflex
from ukflex import scenes

PKG = Path(__file__).resolve().parents[1] / "python" / "ukflex"
ENV = dict(os.environ, MPLBACKEND="Agg")

#: scene.py <-> system.py (Scene.build imports System lazily): owned by the core rewrite.
KNOWN_CYCLES: list = []


def _modules():
    """{dotted name: path} of every Python module of the package."""
    out = {}
    for path in PKG.rglob("*.py"):
        parts = path.relative_to(PKG.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


MODULES = _modules()


def _imports(name, path):
    """[(imported module, imported names, enclosing function or None)] of every import in a file,
    relative imports resolved."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = []

    def visit(node, func):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and getattr(child.test, "id", None) == "TYPE_CHECKING":
                continue  # annotations only: not a dependency
            f = child.name if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)) and func is None else func
            if isinstance(child, ast.Import):
                out.extend((a.name, [], func) for a in child.names)
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package.split(".")
                    base = base[: len(base) - child.level + 1]
                    mod = ".".join(base + ([child.module] if child.module else []))
                else:
                    mod = child.module or ""
                out.append((mod, [a.name for a in child.names], func))
            visit(child, f)

    visit(tree, None)
    return out


def _edges(name, path):
    """Modules of the package that ``name`` imports: ``from P import sub`` depends on the
    submodule ``P.sub`` (the compiled ``_core`` counts as one), ``from P import attr`` on ``P``."""
    for mod, names, func in _imports(name, path):
        if not mod.startswith("ukflex"):
            continue
        subs = [n for n in names if f"{mod}.{n}" in MODULES or n == "_core"]
        if mod in MODULES and (not names or len(subs) < len(names)) and mod != name:
            yield mod
        yield from (f"{mod}.{n}" for n in subs if f"{mod}.{n}" in MODULES)


def test_reference_never_imports_the_rest_of_ukflex():
    for name, path in MODULES.items():
        if not name.startswith("ukflex.reference"):
            continue
        for mod, names, _ in _imports(name, path):
            assert not mod.startswith("ukflex") or mod.startswith("ukflex.reference"), (name, mod)
            assert "_core" not in mod and "_core" not in names, (name, mod, names)


STUDIES = PKG.parents[1] / "studies"


def _study_modules():
    """{dotted name: path} of the repository's studies/ and of the wheel's benchmarks (both run on
    the public API only)."""
    out = {f"studies.{p.stem}": p for p in sorted(STUDIES.glob("*.py"))}
    out.update({n: p for n, p in MODULES.items() if n.startswith("ukflex.benchmarks")})
    return out


def test_studies_are_not_in_the_wheel_and_the_library_does_not_import_them():
    assert not (PKG / "studies").exists() and (STUDIES / "__main__.py").exists()
    assert 'python-source = "python"' in (PKG.parents[1] / "pyproject.toml").read_text()
    for name, path in MODULES.items():
        bad = [mod for mod, _, _ in _imports(name, path) if mod == "studies" or mod.startswith("studies.")]
        assert not bad, f"{name} imports {bad}"


def test_studies_use_only_public_names():
    for name, path in _study_modules().items():
        for mod, names, _ in _imports(name, path):
            if mod.startswith("ukflex"):
                assert not any(p.startswith("_") for p in mod.split(".")), f"{name} imports private module {mod}"
                assert not [n for n in names if n.startswith("_")], f"{name} imports private {names} from {mod}"
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute):
                assert node.attr != "core", f"{name}:{node.lineno} reaches into System.core"
                private = node.attr.startswith("_") and not node.attr.startswith("__")
                assert not private, f"{name}:{node.lineno} uses private attribute {node.attr}"


#: The rooms of the package (docs/architecture.md) and the rooms each may import. The base
#: (``errors``, ``arguments``, ``_core``) is open to every room; ``ukflex/__init__.py`` (the public
#: names) and ``__main__`` may import any room.
ROOMS = {
    "reference": set(),                                          # the independent NumPy model
    "analysis": {"reference"},                                   # works on the System it is given
    "model": {"analysis"},                                       # System's documented analysis methods delegate
    "results": set(),
    "run": {"model", "results", "analysis", "reference"},
    "benchmarks": {"model", "results", "analysis", "run", "reference"},  # ukflex paper, ukflex bench
    "cli": {"model", "results", "analysis", "run", "reference", "benchmarks"},
}
#: (module, imported module) edges allowed against the room rules, each with its reason.
ROOM_EXCEPTIONS = {
    # the method lists a scene file's [solver] table is checked against; they move into the core
    # with the run-option rules (issue 29 item 3, the Rust side)
    ("ukflex.model.scenefile", "ukflex.run.simulate"): "method names",
    # the FE build runs with one BLAS thread (the one thread-limit helper, threadpoolctl optional)
    ("ukflex.model.fe3", "ukflex.reference._blas"): "BLAS threads",
}
BASE = {"ukflex.errors", "ukflex.arguments", "ukflex._core"}


def _room(module):
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ROOMS else None


def test_rooms_import_only_what_their_rules_allow():
    bad = []
    for name, path in MODULES.items():
        room = _room(name)
        if room is None:
            continue
        for e in set(_edges(name, path)):
            other = _room(e)
            if e in BASE or other == room or (name, e) in ROOM_EXCEPTIONS:
                continue
            if e == "ukflex" and room in ("benchmarks", "cli"):
                continue  # the public names
            if other is None or other not in ROOMS[room]:
                bad.append(f"{name} -> {e}")
    assert bad == []


def test_base_imports_no_room():
    for name in BASE - {"ukflex._core"}:
        assert {e for e in _edges(name, MODULES[name]) if e not in BASE} == set(), name


def _cycles(graph):
    """The strongly connected components of more than one node (Tarjan)."""
    cycles = []
    index, low, stack, on_stack, counter = {}, {}, [], set(), [0]

    def strongconnect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = set()
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.add(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(comp)

    for v in sorted(graph):
        if v not in index:
            strongconnect(v)
    return cycles


def test_no_import_cycles():
    graph = {name: set(_edges(name, path)) for name, path in MODULES.items()}
    cycles = _cycles(graph)
    assert [c for c in cycles if c not in KNOWN_CYCLES] == []


RUST = PKG.parents[1] / "rust"


def _rust_graph():
    """Which Rust file uses which (``crate::a::b`` and ``super::x`` paths in code, comments and
    tests left out; a file using its own parent module is the module tree, not an import)."""
    import re

    files = {}
    for f in RUST.rglob("*.rs"):
        parts = list(f.relative_to(RUST).with_suffix("").parts)
        if f.name == "tests.rs" or parts[0] == "bindings":
            continue
        if parts[-1] == "mod":
            parts = parts[:-1]
        files[tuple(parts) if parts != ["lib"] else ()] = f

    def resolve(path):
        for k in range(len(path), 0, -1):
            if tuple(path[:k]) in files:
                return tuple(path[:k])
        return None

    graph = {}
    for mod, f in files.items():
        code = re.sub(r"//[^\n]*", "", f.read_text().split("#[cfg(test)]")[0])
        out = {resolve(m.split("::")) for m in re.findall(r"crate::((?:[a-z_0-9]+::)*[A-Za-z_0-9]+)", code)}
        base = list(mod[:-1])
        out |= {resolve(base + m.split("::")) for m in re.findall(r"super::((?:[a-z_0-9]+::)*[A-Za-z_0-9]+)", code)}
        graph["/".join(mod)] = {"/".join(r) for r in out if r is not None and r != mod and r != tuple(base)}
    return graph


def test_no_rust_file_imports_a_file_that_imports_it():
    """The core's layers (docs/architecture.md): no cycle among its files (there were two: the
    spatial builder and the model, the initial correction's two steps)."""
    graph = _rust_graph()
    assert {"model", "model/spatial", "uk/dense", "data", "correct/initial"} <= set(graph)  # it reads the tree
    assert "data" in graph["uk/dense"] and "model" in graph["data"]  # and sees imports
    assert _cycles(graph) == []


def test_extreme_is_not_exported_at_top_level():
    r = subprocess.run([sys.executable, "-c", "import ukflex, sys; print('extreme' in dir(ukflex), "
                        "any(m.split('.')[0] == 'studies' or m.startswith('ukflex.benchmarks') for m in sys.modules))"],
                       capture_output=True, text=True, env=ENV)
    assert r.returncode == 0 and r.stdout.split() == ["False", "False"], r.stdout + r.stderr
    assert "extreme" not in ukflex.__all__


# ---------------------------------------------------------------------------- built-in scenes
def test_gravity_forms():
    g = scenes.gravity_vector
    assert g(True) == (0.0, -9.81) and g(False) is None and g(None) is None
    assert g(3.0) == (0.0, -3.0) and g(np.float64(2.0)) == (0.0, -2.0) and g(0) == (0.0, -0.0)
    assert g((1, -2)) == (1.0, -2.0) and g(np.array([0.5, 0.0])) == (0.5, 0.0)
    with pytest.raises(ValueError, match="2-vector"):
        g((1.0, 2.0, 3.0))
    for gravity, expected in ((True, [0.0, -9.81]), (False, None), (1.62, [0.0, -1.62]), ((0.0, -3.0), [0.0, -3.0])):
        for fn in scenes.SCENES.values():
            assert fn(gravity=gravity).to_dict().get("gravity") == expected, (fn.__name__, gravity)


#: Functions over 150 lines that docs/architecture.md names and argues (Hairer's step loops).
LONG_FUNCTIONS = {("integrate/dopri5.rs", "step"), ("integrate/radau_m.rs", "step"), ("integrate/radau5.rs", "step")}


def _rust_functions(path):
    """[(name, lines)] of the functions of a Rust file (from ``fn`` to its closing brace at the
    same indentation)."""
    import re

    lines = path.read_text().split("\n")
    out = []
    for i, line in enumerate(lines):
        m = re.match(r"^(\s*)(?:pub(?:\([^)]*\))?\s+)?(?:const\s+)?(?:unsafe\s+)?fn\s+(\w+)", line)
        if m and not line.rstrip().endswith(";"):
            end = next((j for j in range(i, len(lines)) if lines[j] == m.group(1) + "}"), None)
            if end is not None:
                out.append((m.group(2), end - i + 1))
    return out


def test_no_rust_file_over_700_lines_and_no_long_function_but_the_documented():
    """Issue 29's sizes: every Rust file at most 700 lines; functions at most 150 lines, but the
    integrators' step loops that docs/architecture.md names."""
    files = sorted(RUST.rglob("*.rs"))
    assert len(files) > 80
    big = {str(f.relative_to(RUST)): n for f in files if (n := len(f.read_text().split("\n"))) > 700}
    assert big == {}
    long = {(str(f.relative_to(RUST)), name) for f in files for name, n in _rust_functions(f) if n > 150}
    assert long == LONG_FUNCTIONS
    doc = (PKG.parents[1] / "docs" / "architecture.md").read_text()
    assert all(Path(f).name in doc for f, _ in LONG_FUNCTIONS)
    # the measure sees a long function: the biggest one is over 150 lines
    assert max(n for f in files for _, n in _rust_functions(f)) > 150


#: Python functions over 150 lines of code that docs/architecture.md names and argues.
LONG_PY_FUNCTIONS = {("python/ukflex/run/simulate.py", "_simulate_scipy")}


def test_no_python_function_over_150_lines_but_the_documented():
    """Issue 29's sizes in the package: at most 150 lines of code a function (after its
    docstring), but scipy's driver loop that docs/architecture.md names."""
    root = PKG.parents[1]
    long = set()
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                first = node.body[0]
                doc = isinstance(first, ast.Expr) and isinstance(getattr(first, "value", None), ast.Constant)
                if node.end_lineno - (first.end_lineno if doc else node.lineno) > 150:
                    long.add((str(path.relative_to(root)), node.name))
    assert long == LONG_PY_FUNCTIONS
    doc = (root / "docs" / "architecture.md").read_text()
    assert all(name in doc for _, name in LONG_PY_FUNCTIONS)
