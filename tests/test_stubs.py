"""python/ukflex/_core.pyi against the compiled module: names, parameter names, kinds and defaults.

PyO3 gives every compiled function a ``__text_signature__``, so ``inspect.signature`` reads the
real signature; the stub is parsed with ``ast``.  Both directions are checked: whatever the
module exposes publicly is in the stub, and whatever the stub declares exists with that
signature (a private method is checked when the stub declares it).
"""

import ast
import inspect
from pathlib import Path

import ukflex._core as core

STUB = Path(__file__).resolve().parents[1] / "python" / "ukflex" / "_core.pyi"


def _stub_params(fn: ast.FunctionDef):
    """[(name, kind, default)] of a stub function, without self/cls."""
    a = fn.args
    positional = a.posonlyargs + a.args
    defaults = [inspect.Parameter.empty] * (len(positional) - len(a.defaults)) + [
        ast.literal_eval(d) for d in a.defaults
    ]
    out = [(p.arg, "positional", d) for p, d in zip(positional, defaults)]
    out += [(p.arg, "keyword-only", inspect.Parameter.empty if d is None else ast.literal_eval(d))
            for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    if a.vararg:
        out.append((a.vararg.arg, "*args", inspect.Parameter.empty))
    if a.kwarg:
        out.append((a.kwarg.arg, "**kwargs", inspect.Parameter.empty))
    return [p for p in out if p[0] not in ("self", "cls")]


_KIND = {
    inspect.Parameter.POSITIONAL_ONLY: "positional",
    inspect.Parameter.POSITIONAL_OR_KEYWORD: "positional",
    inspect.Parameter.KEYWORD_ONLY: "keyword-only",
    inspect.Parameter.VAR_POSITIONAL: "*args",
    inspect.Parameter.VAR_KEYWORD: "**kwargs",
}


def _runtime_params(obj):
    sig = inspect.signature(obj)
    return [(p.name, _KIND[p.kind], p.default) for p in sig.parameters.values() if p.name not in ("self", "cls")]


def _is_property(fn: ast.FunctionDef) -> bool:
    return any(isinstance(d, ast.Name) and d.id == "property" for d in fn.decorator_list)


def stub_problems(stub_text: str, module) -> list:
    """Every difference between the stub text and the compiled module, as readable lines."""
    tree = ast.parse(stub_text)
    problems = []
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    functions = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    assigned = {t.id for n in tree.body if isinstance(n, ast.Assign) for t in n.targets if isinstance(t, ast.Name)}
    assigned |= {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)}
    stub_public = {n for n in set(classes) | set(functions) | assigned if not n.startswith("_")}
    runtime_public = {n for n in dir(module) if not n.startswith("_")}
    for n in sorted(runtime_public - stub_public):
        problems.append(f"{module.__name__}.{n} is missing from the stub")
    for n in sorted(stub_public - runtime_public):
        problems.append(f"{module.__name__}.{n} is in the stub but not in the module")
    if "__all__" not in assigned and hasattr(module, "__all__"):
        problems.append(f"{module.__name__}.__all__ is missing from the stub")
    if "__all__" in assigned:
        stub_all = next(ast.literal_eval(n.value) for n in tree.body if isinstance(n, ast.Assign)
                        and any(isinstance(t, ast.Name) and t.id == "__all__" for t in n.targets))
        if sorted(stub_all) != sorted(getattr(module, "__all__", [])):
            problems.append(f"__all__ differs: stub {sorted(stub_all)}, module {sorted(module.__all__)}")
    for name, fn in functions.items():
        if hasattr(module, name) and _stub_params(fn) != _runtime_params(getattr(module, name)):
            problems.append(f"{name}{_stub_params(fn)} != runtime {_runtime_params(getattr(module, name))}")
    for cname, cdef in classes.items():
        cls = getattr(module, cname, None)
        if cls is None:
            continue
        stub_bases = [b.id for b in cdef.bases if isinstance(b, ast.Name)]
        runtime_bases = [b.__name__ for b in cls.__bases__ if b is not object]
        if stub_bases != runtime_bases:
            problems.append(f"class {cname}: stub bases {stub_bases}, runtime bases {runtime_bases}")
        members = {n.name: n for n in cdef.body if isinstance(n, ast.FunctionDef)}
        runtime_members = {n for n, v in vars(cls).items() if not n.startswith("_") and not isinstance(v, type)}
        if issubclass(cls, BaseException):
            continue  # exception classes add nothing of their own
        for n in sorted(runtime_members - set(members)):
            problems.append(f"{cname}.{n} is missing from the stub")
        if "__new__" in members or "__init__" in members:
            ctor = members.get("__new__") or members["__init__"]
            if _stub_params(ctor) != _runtime_params(cls):
                problems.append(f"{cname}({_stub_params(ctor)}) != runtime {cname}{_runtime_params(cls)}")
        for n, fn in members.items():
            if n in ("__new__", "__init__"):
                continue
            if n not in vars(cls):
                problems.append(f"{cname}.{n} is in the stub but not in the module")
                continue
            attr = vars(cls)[n]
            is_data = inspect.isgetsetdescriptor(attr) or inspect.ismemberdescriptor(attr)
            if _is_property(fn) != is_data:
                problems.append(f"{cname}.{n}: stub {'property' if _is_property(fn) else 'method'}, runtime "
                                f"{'attribute' if is_data else 'method'}")
            elif not is_data and _stub_params(fn) != _runtime_params(attr):
                problems.append(f"{cname}.{n}{_stub_params(fn)} != runtime {_runtime_params(attr)}")
    return problems


def test_stub_matches_the_compiled_module():
    problems = stub_problems(STUB.read_text(), core)
    assert not problems, "\n".join(problems)


def test_the_check_catches_a_drifted_stub():
    """The drift the stub once had (keyword ``body_name`` for the real ``body``, a missing
    default) and a method the stub does not know are all reported."""
    text = STUB.read_text()
    drifted = (text.replace("def beam_shape(self, body: str", "def beam_shape(self, body_name: str")
               .replace('def set_pseudoinverse(self, kind: str = "auto")', "def set_pseudoinverse(self, kind: str)")
               .replace("    def rank(self) -> Tuple[int, float]:", "    def rank_(self) -> Tuple[int, float]:")
               .replace("    @property\n    def n_coords(self) -> int: ...", "    def n_coords(self) -> int: ..."))
    assert drifted != text
    problems = "\n".join(stub_problems(drifted, core))
    assert "beam_shape" in problems and "body_name" in problems
    assert "set_pseudoinverse" in problems and "'auto'" in problems
    assert "System.rank is missing from the stub" in problems and "System.rank_ is in the stub but not" in problems
    assert "System.n_coords: stub method, runtime attribute" in problems
