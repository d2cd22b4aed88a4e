"""The type stubs: `strata/_strata.pyi` and `py.typed` are installed with the
package, and the stubs name every public class, function and member of the native
module `strata._strata`, with the parameters the module's own signatures give."""

import ast
import inspect
import pathlib

import pytest

import strata
from strata import _strata

PACKAGE = pathlib.Path(strata.__file__).resolve().parent
ERRORS = {"StrataError", "StackError", "TableError", "SurfaceError", "SceneError", "SolveError", "LawError"}


def stub_tree() -> ast.Module:
    path = PACKAGE / "_strata.pyi"
    assert path.is_file(), f"{path} is not installed (maturin's python-source includes it)"
    return ast.parse(path.read_text(encoding="utf-8"))


def top_level(tree: ast.Module) -> dict:
    """Public names the stub declares at module level: name -> node."""
    names = {}
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node
    return {n: v for n, v in names.items() if not n.startswith("_") or n == "__version__"}


def members(cls: ast.ClassDef) -> dict:
    """Functions of a stub class (overloads merged): name -> list of FunctionDef."""
    out = {}
    for node in cls.body:
        if isinstance(node, ast.FunctionDef):
            out.setdefault(node.name, []).append(node)
    return out


def params(fn: ast.FunctionDef) -> list:
    a = fn.args
    names = [p.arg for p in a.posonlyargs + a.args + a.kwonlyargs]
    return [n for n in names if n not in ("self", "cls")]


def decorators(fn: ast.FunctionDef) -> set:
    return {d.id for d in fn.decorator_list if isinstance(d, ast.Name)}


def native_public() -> set:
    return {n for n in dir(_strata) if not n.startswith("_")} | {"__version__"}


def test_py_typed_is_installed():
    assert (PACKAGE / "py.typed").is_file(), "py.typed is not installed with the package"


def test_stubs_name_every_public_name_of_the_native_module():
    declared = set(top_level(stub_tree()))
    native = native_public()
    assert native - declared == set(), f"missing from _strata.pyi: {sorted(native - declared)}"
    assert declared - native == set(), f"in _strata.pyi but not in the module: {sorted(declared - native)}"


def test_stub_classes_name_every_member_with_its_parameters():
    tree = stub_tree()
    checked = 0
    for name, node in top_level(tree).items():
        obj = getattr(_strata, name)
        if not isinstance(node, ast.ClassDef):
            if isinstance(node, ast.FunctionDef):
                assert callable(obj), name
                sig = inspect.signature(obj)
                assert params(node) == list(sig.parameters), f"{name}: {params(node)} vs {sig}"
                checked += 1
            continue
        assert isinstance(obj, type), f"{name} is a class in the stubs, not in the module"
        if name in ERRORS:
            assert issubclass(obj, ValueError), name
            continue
        declared = members(node)
        native = {m for m in dir(obj) if not m.startswith("_")}
        assert native - set(declared) == set(), f"{name}: missing from the stubs: {sorted(native - set(declared))}"
        extra = {m for m in set(declared) - native if not (m.startswith("__") and hasattr(obj, m))}
        assert extra == set(), f"{name}: in the stubs but not in the module: {sorted(extra)}"
        for m, fns in declared.items():
            if m.startswith("__") and m != "__new__":
                continue
            raw = inspect.getattr_static(obj, m) if m != "__new__" else obj
            if isinstance(raw, property) or type(raw).__name__ == "getset_descriptor":
                assert all("property" in decorators(f) for f in fns), f"{name}.{m} is a property"
                checked += 1
                continue
            assert not any("property" in decorators(f) for f in fns), f"{name}.{m} is not a property"
            try:
                sig = inspect.signature(raw if m == "__new__" else getattr(obj, m))
            except (TypeError, ValueError):
                pytest.fail(f"{name}.{m}: the native module gives no signature")
            want = [p for p in sig.parameters if p not in ("self", "cls", "$self", "$cls")]
            for f in fns:
                assert params(f) == want, f"{name}.{m}: stub {params(f)} vs module {want}"
            static = isinstance(inspect.getattr_static(obj, m), staticmethod) if m != "__new__" else False
            if static:
                assert all("staticmethod" in decorators(f) for f in fns), f"{name}.{m} is a staticmethod"
            checked += 1
    assert checked > 60, checked


def test_mypy_stubtest_agrees_with_the_module():
    """mypy's stubtest: every stub's kind, parameters, defaults and finality against the
    runtime module. Needs mypy (python/ci.sh installs it); skipped without it unless
    STRATA_REQUIRE_TOOLS=1 (CI)."""
    import os
    import subprocess
    import sys

    try:
        import mypy  # noqa: F401
    except ImportError:
        if os.environ.get("STRATA_REQUIRE_TOOLS") == "1":
            pytest.fail("mypy is not installed (STRATA_REQUIRE_TOOLS=1): pip install mypy")
        pytest.skip("mypy is not installed: pip install mypy to run stubtest")
    run = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "strata._strata"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout + run.stderr
