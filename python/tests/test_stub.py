"""The stub `hylc/_hylc.pyi` carries the module's docstrings and signatures; every public function and class has a
numpydoc docstring."""

import ast
import importlib.util
import inspect
from pathlib import Path

import pytest

import hylc
from hylc import _hylc

STUB = Path(__file__).resolve().parents[1] / "hylc" / "_hylc.pyi"
TOOL = Path(__file__).resolve().parents[1] / "stubdoc.py"


def stub_tree():
    return ast.parse(STUB.read_text())


def test_the_stub_has_the_module_docstrings():
    spec = importlib.util.spec_from_file_location("stubdoc", TOOL)
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    text = STUB.read_text()
    assert tool.render(text, _hylc) == text, "run `python python/stubdoc.py` after changing a docstring"


def test_every_public_name_is_in_the_stub_with_its_parameters():
    defs = {n.name: n for n in stub_tree().body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    for name in hylc.__all__:
        obj = getattr(hylc, name)
        if not (inspect.isclass(obj) or callable(obj)):
            continue
        assert name in defs, f"{name} is not in the stub"
        if inspect.isbuiltin(obj):
            node = defs[name]
            stub_params = [a.arg for a in node.args.args + node.args.kwonlyargs]
            assert stub_params == list(inspect.signature(obj).parameters), name


@pytest.mark.parametrize("name", [n for n in hylc.__all__ if callable(getattr(hylc, n))])
def test_numpydoc_sections(name):
    obj = getattr(hylc, name)
    doc = inspect.getdoc(obj) or ""
    assert doc, f"{name} has no docstring"
    if inspect.isclass(obj) and issubclass(obj, Exception):
        return
    members = [obj] if not inspect.isclass(obj) else [
        getattr(obj, k) for k in vars(obj) if not k.startswith("_") and callable(getattr(obj, k))]
    for m in members:
        d = inspect.getdoc(m) or ""
        assert d, f"{name}.{getattr(m, '__name__', '')} has no docstring"
        try:
            params = [p for p in inspect.signature(m).parameters if p not in ("self", "$self")]
        except (TypeError, ValueError):
            params = []
        if params:
            assert "Parameters\n----------" in d, f"{name}.{m.__name__}: no Parameters section"
    if not inspect.isclass(obj):
        assert "Returns\n-------" in doc or "Raises\n------" in doc, f"{name}: no Returns or Raises section"
