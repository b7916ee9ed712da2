"""The type stubs (flexmb/_flexmb.pyi) describe the module as it is: every
class, function, method and attribute they declare exists, and every public
name of the module is declared; everything public has a docstring."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import flexmb
from flexmb import _flexmb

STUB = Path(flexmb.__file__).with_name("_flexmb.pyi")


def declared():
    tree = ast.parse(STUB.read_text())
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            members = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
            out[node.name] = members
        elif isinstance(node, ast.FunctionDef):
            out[node.name] = None
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            if node.target.id.startswith("_") and not node.target.id.startswith("__"):
                continue  # a type alias of the stub
            out[node.target.id] = None
    return out


def test_the_stubs_are_installed_with_the_package():
    assert STUB.is_file()
    assert STUB.with_name("py.typed").is_file()


def test_every_declared_name_exists():
    for name, members in declared().items():
        assert hasattr(_flexmb, name), f"the stub declares {name}, the module has none"
        for m in members or ():
            if m == "__init__":
                continue
            assert hasattr(getattr(_flexmb, name), m), f"{name}.{m} is declared but missing"


def test_every_public_name_is_declared_and_documented():
    stub = declared()
    for name in flexmb.__all__:
        assert name in stub, f"{name} is not in the stub"
        obj = getattr(flexmb, name)
        if inspect.isclass(obj) or callable(obj):
            assert (obj.__doc__ or "").strip(), f"{name} has no docstring"
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            for m, v in vars(obj).items():
                if not m.startswith("_"):
                    assert m in stub[name], f"{name}.{m} is not in the stub"
                    assert (getattr(v, "__doc__", None) or "").strip(), f"{name}.{m} has no docstring"
