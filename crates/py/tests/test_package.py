"""The package's metadata agrees with the native module: every `_native` function and class member
has a type stub and every stub names something real; pyproject.toml builds the module Python imports."""

from __future__ import annotations

import ast
import pathlib
import sys

import pytest

import inbetween
from inbetween import _native

PY = pathlib.Path(__file__).resolve().parents[1]
STUBS = PY / "python" / "inbetween" / "_native.pyi"


def _stubs():
    tree = ast.parse(STUBS.read_text())
    functions = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {
        n.name: {m.name for m in n.body if isinstance(m, ast.FunctionDef)} for n in tree.body if isinstance(n, ast.ClassDef)
    }
    names = {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target] if isinstance(t, ast.Name)}
    return functions, classes, names


def test_every_native_function_and_member_has_a_stub_and_back():
    functions, classes, names = _stubs()
    native = {n for n in dir(_native) if not n.startswith("__")}
    native_functions = {n for n in native if callable(getattr(_native, n)) and not isinstance(getattr(_native, n), type)}
    native_classes = {n for n in native if isinstance(getattr(_native, n), type)}
    assert native_functions - functions == set(), "native functions without a stub"
    assert functions - native_functions == set(), "stubs of functions the module lacks"
    assert native_classes == set(classes), "classes: native vs stubs"
    for cls, stubbed in classes.items():
        members = {n for n in vars(getattr(_native, cls)) if not n.startswith("__") or n == "__init__"}
        members.discard("__init__")
        stubbed = {m for m in stubbed if m != "__init__" and not (m.startswith("__") and m.endswith("__"))}
        assert members - stubbed == set(), f"{cls}: members without a stub"
        assert stubbed - members == set(), f"{cls}: stubs of members the class lacks"
    assert "__version__" in names and _native.__version__ == inbetween.__version__


def test_pyproject_builds_this_module():
    if sys.version_info < (3, 11):
        pytest.skip("skipped: tomllib needs Python 3.11")
    import tomllib

    project = tomllib.loads((PY / "pyproject.toml").read_text())
    assert project["build-system"]["build-backend"] == "maturin"
    maturin = project["tool"]["maturin"]
    assert maturin["module-name"] == "inbetween._native" and _native.__name__ == "inbetween._native"
    assert (PY / maturin["python-source"] / "inbetween" / "py.typed").is_file()
    assert any(d.startswith("numpy") for d in project["project"]["dependencies"])
    cargo = tomllib.loads((PY / "Cargo.toml").read_text())
    assert cargo["lib"]["name"] == "_native" and "cdylib" in cargo["lib"]["crate-type"]
    # Every Python module of the package imports (no stale names against the native module).
    for mod in ("camera", "face", "ibk", "mocap", "script", "batch"):
        assert getattr(inbetween, mod, None) is not None or __import__(f"inbetween.{mod}")
